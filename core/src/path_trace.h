#pragma once

// Backtracing from a target answered by a targeted solve (private to core).

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/shortest_path.h"
#include "geodex/triangle_mesh.h"
#include "ich/ich_solver.h"

namespace geodex {

// What a backtrace reads per internal vertex: a DistanceField's arrays, or a targeted solve's
// still in its workspace.
struct VertexPaths {
  const double* distance;
  const VertexOrigin* origin;
};

// The path from the target (`where` names it in file terms) to its nearest source.
absl::StatusOr<GeodesicPath> TraceFromTarget(const TriangleMesh& mesh, const VertexPaths& field,
                                             const ich::TargetResult& result,
                                             const SurfacePoint& where);

}  // namespace geodex
