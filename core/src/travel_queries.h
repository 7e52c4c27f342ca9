#pragma once

// The travel-cost answers (geodex/travel_cost.h) behind the public queries: ComputeDistanceField,
// ComputePointValues, ComputeShortestPath(s) and ComputeDistanceMatrix call these when their
// options carry a travel cost, so every product built on them speaks seconds. Each converts the
// weighted engine's costs to seconds; none adds a rule of its own.

#include <memory>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/travel_cost.h"
#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"

namespace geodex {

absl::StatusOr<DistanceField> ComputeTravelField(const TriangleMesh& mesh,
                                                 const std::vector<SurfacePoint>& sources,
                                                 const GeodesicOptions& options);

// InvalidArgument naming "travel" when the query asks for directions.
absl::StatusOr<PointValues> ComputeTravelPointValues(const TriangleMesh& mesh,
                                                     const PointQuery& query);

class RegionSurface;

// Travel times at points for many queries with one mesh and one travel cost (a matrix's rows):
// the weighted graph (or, where every passable face weighs the same, the exact engine's union mesh,
// weighted_regions.h) is built once and shared, read-only, by every query (thread-safe).
class TravelPointSolver {
 public:
  // `options` carry the travel cost; `sources` and `points`, when known, are what Solve will be
  // given (WeightedSurface::Build's seeds and anchors: a Solve with other points strictly inside
  // faces or edges builds a graph of its own). Errors: as ComputeTravelPointValues.
  static absl::StatusOr<TravelPointSolver> Create(const TriangleMesh& mesh,
                                                  const GeodesicOptions& options,
                                                  const std::vector<SurfacePoint>& sources = {},
                                                  const std::vector<SurfacePoint>& points = {});
  // Times from `sources` at `points`, in seconds (ComputeTravelPointValues without directions).
  absl::StatusOr<PointValues> Solve(const std::vector<SurfacePoint>& sources,
                                    const std::vector<SurfacePoint>& points,
                                    bool covers_surface = false) const;

 private:
  TravelPointSolver(TravelCost travel, std::shared_ptr<const WeightedSurface> surface,
                    std::shared_ptr<const RegionSurface> regions, WeightedSurface::Limits limits)
      : travel_(std::move(travel)),
        surface_(std::move(surface)),
        regions_(std::move(regions)),
        limits_(limits) {}
  TravelCost travel_;
  std::shared_ptr<const WeightedSurface> surface_;  // built for the query, or TravelCost::graph
  std::shared_ptr<const RegionSurface> regions_;    // instead, where RegionsServe
  WeightedSurface::Limits limits_;                  // the query's
};

// One least-time path per target (each path's `length` is its length in metres; `distance` its
// time in seconds); an unreachable target has +inf and no points.
absl::StatusOr<PathsQueryResult> ComputeTravelPaths(const TriangleMesh& mesh,
                                                    const SurfacePoint& from,
                                                    const std::vector<SurfacePoint>& tos,
                                                    const GeodesicOptions& options);

}  // namespace geodex
