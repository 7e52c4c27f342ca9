#pragma once

// Mesh ids: SHA-256 (lowercase hex) of the canonical encoding of a parsed mesh, as documented on
// geodex.v1.Mesh.name in proto/geodex/v1/geodex.proto.

#include <array>
#include <cstdint>
#include <string>

#include "absl/strings/string_view.h"
#include "geodex/mesh_data.h"

namespace geodex::server {

// Incremental SHA-256 (FIPS 180-4).
class Sha256 {
 public:
  Sha256();
  void Update(const void* data, size_t size);
  std::array<uint8_t, 32> Finish();

 private:
  void Block(const uint8_t* p);
  std::array<uint32_t, 8> h_;
  std::array<uint8_t, 64> buffer_{};
  size_t buffered_ = 0;
  uint64_t total_ = 0;
};

// Lowercase hex SHA-256 of `bytes`.
std::string Sha256Hex(absl::string_view bytes);

// The canonical encoding: "GDXM", uint32 LE vertex count, uint32 LE face count, float64 LE
// positions (3 per vertex, file order), uint32 LE face corners (3 per face, file order).
std::string CanonicalMeshEncoding(const MeshData& mesh);

// SHA-256 hex of CanonicalMeshEncoding(mesh), computed without materialising the encoding.
std::string ComputeMeshId(const MeshData& mesh);

// True for 64 lowercase hex digits.
bool IsMeshId(absl::string_view s);

}  // namespace geodex::server
