#pragma once

// The travel-cost answers (geodex/travel_cost.h) behind the public queries: ComputeDistanceField,
// ComputePointValues, ComputeShortestPath(s) and ComputeDistanceMatrix call these when their
// options carry a travel cost, so every product built on them speaks seconds. Each converts the
// weighted engine's costs to seconds; none adds a rule of its own.

#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

absl::StatusOr<DistanceField> ComputeTravelField(const TriangleMesh& mesh,
                                                 const std::vector<SurfacePoint>& sources,
                                                 const GeodesicOptions& options);

// InvalidArgument naming "travel" when the query asks for directions.
absl::StatusOr<PointValues> ComputeTravelPointValues(const TriangleMesh& mesh,
                                                     const PointQuery& query);

// One least-time path per target (each path's `length` is its length in metres; `distance` its
// time in seconds); an unreachable target has +inf and no points.
absl::StatusOr<PathsQueryResult> ComputeTravelPaths(const TriangleMesh& mesh,
                                                    const SurfacePoint& from,
                                                    const std::vector<SurfacePoint>& tos,
                                                    const GeodesicOptions& options);

}  // namespace geodex
