#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "geodex/mesh_data.h"

namespace geodex {

enum class MeshFormat { kAuto, kOff, kObj, kPly, kStl };

// Limits that keep a reader from allocating without bound on hostile input. Counts in a header are
// checked against these and against the bytes actually present before anything is reserved.
struct ReadLimits {
  uint64_t max_vertices = 50'000'000;
  uint64_t max_faces = 100'000'000;
  uint64_t max_decompressed_bytes = uint64_t{8} << 30;  // gzip expansion bound
};

// Reads a mesh file: OFF, OBJ (polygons fan-triangulated, 1-based and negative indices), PLY
// (ascii, binary little/big endian, any property order), STL (ascii/binary; identical positions
// welded), each optionally gzip-compressed (detected by magic bytes). The format comes from the
// extension (after stripping .gz) and falls back to sniffing the content. Errors name the file and
// position
// ("bunny.off: line 12: expected 3 coordinates").
absl::StatusOr<MeshData> ReadMeshFile(const std::string& path, const ReadLimits& limits = {});

// Same, from bytes in memory (the server receives uploads this way). `name` is used in messages
// and, with kAuto, its extension picks the format.
absl::StatusOr<MeshData> ReadMeshFromBuffer(absl::string_view bytes, MeshFormat format,
                                            const std::string& name, const ReadLimits& limits = {});

// Optional per-vertex payload for writers: a scalar (e.g. distance; +inf allowed) and/or an RGB
// colour.
struct VertexAttributes {
  std::vector<double> scalar;   // empty or vertex_count values
  std::vector<uint8_t> colors;  // empty or 3 * vertex_count bytes
};

// Writes OFF (ascii; colours as COFF when present, scalars are not representable and are dropped).
absl::Status WriteMeshOff(const std::string& path, const MeshData& mesh,
                          const VertexAttributes& attributes = {});
// Writes binary little-endian PLY with optional `float64 distance` and `uchar red/green/blue`.
absl::Status WriteMeshPly(const std::string& path, const MeshData& mesh,
                          const VertexAttributes& attributes = {});

}  // namespace geodex
