#pragma once

// Backtracing from a target answered by a targeted solve (private to core).

#include <array>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/shortest_path.h"
#include "geodex/triangle_mesh.h"
#include "ich/ich_solver.h"
#include "ich/region_links.h"

namespace geodex {

// What a backtrace reads per internal vertex: a DistanceField's arrays, or a targeted solve's
// still in its workspace. On the union of a weighted surface's regions (weighted_regions.h) also
// the boundary points' origins and the links that place them: a path then runs on through the
// points (ich/region_links.h's kBoundaryPointTag) to its source.
struct VertexPaths {
  const double* distance;
  const VertexOrigin* origin;
  const VertexOrigin* point_origin = nullptr;
  const ich::RegionLinks* links = nullptr;
};

// The path from the target (`where` names it in file terms) to its nearest source.
absl::StatusOr<GeodesicPath> TraceFromTarget(const TriangleMesh& mesh, const VertexPaths& field,
                                             const ich::TargetResult& result,
                                             const SurfacePoint& where);

// The unit direction (file coordinates) of the first step of that path, read off the solve's
// record in O(1): from a face or edge point straight towards the image of its origin (into the
// neighbouring face when the point lies on the image's edge and the image is beyond it), from a
// vertex as ComputeDirectionField does; 0 0 0 at a source, NaN where unreachable.
std::array<double, 3> TargetDirection(const TriangleMesh& mesh, const VertexPaths& field,
                                      const ich::TargetResult& result);

}  // namespace geodex
