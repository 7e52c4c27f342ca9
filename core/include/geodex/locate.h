#pragma once

// Nearest surface point to a 3D position ("snap a click / a GPS fix onto the mesh").

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// The closest point of triangle (a, b, c) to p, by Voronoi regions of the triangle's vertices,
// edges and interior (Ericson, "Real-Time Collision Detection", 5.1.5). `bary` weights a, b, c
// (non-negative, summing to 1 up to round-off), `point` is the closest point and `distance2` the
// squared distance to it. A vertex region returns that vertex bit-for-bit (distance 0 for a query
// exactly at it). Zero-area triangles are handled as their three edges.
struct TriangleClosestPoint {
  std::array<double, 3> point;
  std::array<double, 3> bary;
  double distance2;
};
TriangleClosestPoint ClosestPointOnTriangle(const std::array<double, 3>& p,
                                            const std::array<double, 3>& a,
                                            const std::array<double, 3>& b,
                                            const std::array<double, 3>& c);

struct LocatedPoint {
  // A face point (f:FACE:B0:B1:B2, barycentrics in the file's corner order), snapped to kEdge or
  // kVertex by the surface-point rules (CanonicalFacePoint, kSurfaceSnap), so that it means the
  // same thing to the solver as the position does.
  SurfacePoint point;
  std::array<double, 3> position{};  // the closest surface point, file coordinates
  double distance = 0;               // |query - position|
};

// Nearest-surface-point queries over the non-degenerate faces of a mesh, accelerated by an AABB
// tree (binned-SAH splits, leaves of <= 4 faces, flat node array) searched depth-first, nearer
// child first, pruning boxes farther than the best face so far. Immutable after construction;
// const queries are thread-safe and allocate nothing. Keeps a pointer to `mesh` (for the file-id
// mapping), which must outlive the locator.
class SurfaceLocator {
 public:
  explicit SurfaceLocator(const TriangleMesh& mesh);

  SurfaceLocator(SurfaceLocator&&) = default;
  SurfaceLocator& operator=(SurfaceLocator&&) = default;

  // The surface point nearest to `xyz` (file coordinates). Exact ties go to the lowest face id.
  // Errors: InvalidArgument for a non-finite coordinate or one so far from the mesh (> 1e150) that
  // squared distances would overflow; FailedPrecondition if the mesh has no non-degenerate face.
  absl::StatusOr<LocatedPoint> Locate(const std::array<double, 3>& xyz) const;

  uint32_t inner_node_count() const { return static_cast<uint32_t>(nodes_.size()); }
  uint64_t MemoryBytes() const;

 private:
  // A subtree: the inner node nodes_[index] (count == 0), or a leaf holding the triangles
  // [index, index + count) of the leaf-ordered arrays below.
  struct Ref {
    uint32_t index = 0;
    uint32_t count = 0;
  };
  // An inner node carries both children's boxes, so one visit reads one cache line. The boxes are
  // floats rounded outward: they still contain their triangles, so box distances stay lower bounds.
  struct alignas(64) Node {
    float lo[2][3], hi[2][3];
    Ref child[2];
  };
  static_assert(sizeof(Node) == 64);
  // The triangle's corners in internal order, copied in leaf order so a leaf reads one
  // contiguous block instead of chasing vertex indices.
  struct Triangle {
    std::array<double, 3> p[3];
  };
  struct BuildScratch;  // per-face boxes and centroids, alive only during construction

  // Builds the subtree over the faces items[begin, end) (reordering them) and returns it with its
  // bounding box {lo[3], hi[3]}.
  Ref Build(const BuildScratch& scratch, std::vector<uint32_t>& items, uint32_t begin, uint32_t end,
            int depth, std::array<double, 6>* bounds);

  const TriangleMesh* mesh_;
  Ref root_;
  std::vector<Node> nodes_;          // inner nodes, parents before children
  std::vector<Triangle> triangles_;  // leaf order
  std::vector<uint32_t> face_ids_;   // leaf order
  // Round-off allowance for pruning, from the extent of the recentred mesh (see Locate).
  double extent_ = 0;
};

// Snapping is never silent: OK when `located` is at most `max_snap` from its query position
// (+inf: any distance), else InvalidArgument "QUERY is D from the surface, farther than the
// maximum snap distance M" (the caller prefixes the option or request field).
absl::Status CheckSnapDistance(const std::array<double, 3>& query, const LocatedPoint& located,
                               double max_snap);

}  // namespace geodex
