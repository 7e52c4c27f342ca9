#pragma once

// Backtracing from a target answered by a targeted solve (private to core).

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/shortest_path.h"
#include "geodex/triangle_mesh.h"
#include "ich/ich_solver.h"

namespace geodex {

// The path from the target (`where` names it in file terms) to its nearest source.
absl::StatusOr<GeodesicPath> TraceFromTarget(const TriangleMesh& mesh, const DistanceField& field,
                                             const ich::TargetResult& result,
                                             const SurfacePoint& where);

}  // namespace geodex
