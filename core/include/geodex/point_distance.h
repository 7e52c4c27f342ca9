#pragma once

#include <cstdint>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// An ESTIMATE of the geodesic distance at a surface point from a finished field, by the paper's
// unfolding (Xin & Wang 2010, section 4): across each edge of the point's face, the source is
// unfolded to the point s' with |s' vi| = di and |s' vj| = dj on the far side of the edge, and the
// estimate is |p s'| when p s' crosses the edge, else the route through the nearer edge end; the
// smallest over the face's edges wins. Exact at vertices and for sources in the point's own face
// (straight line); typically within 0.1% elsewhere on fine meshes (see docs/performance.md).
//
// Several sources: an edge is unfolded only when both its ends have the same nearest source (the
// image of one source is meaningful; two different sources have no common image). The vertex
// routes di + |p vi| are always candidates, so the estimate exists whenever a face vertex is
// reachable; `source` is the label of the winning candidate.
struct PointEstimate {
  double distance = kUnreachable;
  uint32_t source = 0xffffffffu;
};

absl::StatusOr<PointEstimate> EstimateDistanceAt(const TriangleMesh& mesh,
                                                 const DistanceField& field,
                                                 const SurfacePoint& point);

}  // namespace geodex
