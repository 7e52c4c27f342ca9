#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace geodex {

// A triangle soup exactly as a file holds it: what the readers produce and what TriangleMesh is
// built from. Vertex i of the file is vertex i here; faces keep the file's order and the file's
// corner order (polygons are fan-triangulated by the readers, in order).
struct MeshData {
  std::vector<double> positions;  // 3 * vertex_count, x y z interleaved, in file coordinates
  std::vector<uint32_t> faces;    // 3 * face_count, vertex indices (not yet validated)

  size_t vertex_count() const { return positions.size() / 3; }
  size_t face_count() const { return faces.size() / 3; }
};

}  // namespace geodex
