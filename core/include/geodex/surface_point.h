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

// --- The surface-point rules, once for all of geodex (docs/engine.md, "Surface points") ---
//
// A point given on a face or an edge that lies (within round-off) on an edge or at a vertex is
// that edge point or that vertex, wherever it comes from: parsed, located from a position,
// resolved as a source or target, or placed for an estimate. One tolerance, one normalisation,
// one classifier:
//  - barycentrics: negatives clamp to 0, the weights are normalised to sum 1, each weight
//    <= kSurfaceSnap becomes 0 and the others are renormalised; two zeros make the vertex, one
//    zero the edge point between the other two corners (in cyclic order after the zero one, t
//    measured from the first), none the face point;
//  - edge parameters: t <= kSurfaceSnap is the edge's first vertex, t >= 1 - kSurfaceSnap its
//    second.
inline constexpr double kSurfaceSnap = 1e-12;

// The canonical point of face `face` with file corners `file_corners` (file vertex ids, file
// corner order) and weights `bary` in that order (not all zero).
SurfacePoint CanonicalFacePoint(uint32_t face, const std::array<uint32_t, 3>& file_corners,
                                std::array<double, 3> bary);
// The canonical point of the edge point (1 - t) * from + t * to.
SurfacePoint CanonicalEdgePoint(uint32_t from, uint32_t to, double t);
// The canonical form of a point that passed ValidateSurfacePoint (positions come back unchanged).
SurfacePoint CanonicalPoint(const TriangleMesh& mesh, const SurfacePoint& p);

// The position (file coordinates) of a vertex, edge or face point of `mesh` (a position point is
// its own position).
std::array<double, 3> PositionOf(const MeshData& mesh, const SurfacePoint& p);

}  // namespace geodex
