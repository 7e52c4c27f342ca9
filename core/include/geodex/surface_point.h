#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "geodex/mesh_data.h"

namespace geodex {

class TriangleMesh;

// A point on the surface, named in the file's terms (file vertex ids, file face ids and the
// file's corner order), so it means the same thing to every client.
struct SurfacePoint {
  // kPosition: a 3D position (file coordinates) to be snapped onto the surface with
  // SurfaceLocator (geodex/locate.h) before use; solvers reject it.
  enum class Kind : uint8_t { kVertex, kEdge, kFace, kPosition };
  Kind kind = Kind::kVertex;
  uint32_t vertex = 0;                  // kVertex
  uint32_t edge_from = 0, edge_to = 0;  // kEdge: the point (1 - t) * from + t * to
  double t = 0;
  uint32_t face = 0;  // kFace: barycentric in the file's corner order
  std::array<double, 3> bary{};
  std::array<double, 3> position{};  // kPosition

  static SurfacePoint AtVertex(uint32_t v) {
    SurfacePoint p;
    p.kind = Kind::kVertex;
    p.vertex = v;
    return p;
  }
  static SurfacePoint OnEdge(uint32_t from, uint32_t to, double t) {
    SurfacePoint p;
    p.kind = Kind::kEdge;
    p.edge_from = from;
    p.edge_to = to;
    p.t = t;
    return p;
  }
  static SurfacePoint AtPosition(double x, double y, double z) {
    SurfacePoint p;
    p.kind = Kind::kPosition;
    p.position = {x, y, z};
    return p;
  }
  static SurfacePoint InFace(uint32_t f, double b0, double b1, double b2) {
    SurfacePoint p;
    p.kind = Kind::kFace;
    p.face = f;
    p.bary = {b0, b1, b2};
    return p;
  }
};

// Parses a comma list: `17` (vertex), `e:V1:V2:T`, `f:FACE:B0:B1:B2`, `p:X:Y:Z` (a position).
// Checks the syntax only; the mesh checks ranges (see ValidateSurfacePoint). Errors name the
// offending item.
absl::StatusOr<std::vector<SurfacePoint>> ParseSurfacePoints(absl::string_view spec);

// Range and consistency checks against a mesh: unknown vertex or face, an edge that does not
// exist, T outside [0,1], negative barycentrics or ones that do not sum to 1 (within 1e-9).
absl::Status ValidateSurfacePoint(const TriangleMesh& mesh, const SurfacePoint& p);
// The one wording of "point P names vertex V, which does not exist": for checks that know only
// the vertex count (geodexd's, before a stored mesh is loaded).
absl::Status VertexOutOfRange(const SurfacePoint& p, uint32_t vertex, uint32_t vertex_count);

std::string SurfacePointToString(const SurfacePoint& p);

// The position (file coordinates) of a vertex, edge or face point of `mesh` (a position point is
// its own position).
std::array<double, 3> PositionOf(const MeshData& mesh, const SurfacePoint& p);

}  // namespace geodex
