#pragma once

// Mesh ids: the SHA-256 (lowercase hex) of a parsed mesh's canonical encoding, as documented on
// geodex.v1.Mesh.name in proto/geodex/v1/geodex.proto. A core concept: the CLI, the client
// library and geodexd all name a mesh by its content the same way. SHA-256 is OpenSSL's.

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "geodex/mesh_data.h"

struct evp_md_ctx_st;  // OpenSSL's EVP_MD_CTX, kept out of this header

namespace geodex {

// Incremental SHA-256.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;
  void Update(const void* data, size_t size);
  std::array<uint8_t, 32> Finish();

 private:
  struct Free {
    void operator()(evp_md_ctx_st* ctx) const;
  };
  std::unique_ptr<evp_md_ctx_st, Free> ctx_;
};

// Lowercase hex of a digest, and the SHA-256 hex of `bytes`.
std::string HexDigest(const std::array<uint8_t, 32>& digest);
std::string Sha256Hex(absl::string_view bytes);

// The canonical encoding: "GDXM", uint32 LE vertex count, uint32 LE face count, float64 LE
// positions (3 per vertex, file order), uint32 LE face corners (3 per face, file order).
std::string CanonicalMeshEncoding(const MeshData& mesh);
// The canonical encoding back into a mesh. InvalidArgument if malformed.
absl::StatusOr<MeshData> DecodeCanonicalMesh(absl::string_view bytes);

// SHA-256 hex of CanonicalMeshEncoding(mesh), computed without materialising the encoding.
std::string ComputeMeshId(const MeshData& mesh);

// True for 64 lowercase hex digits.
bool IsMeshId(absl::string_view s);

}  // namespace geodex
