#pragma once

// Travel costs on a surface of constant weights per face, by regions (docs/engine.md, "Weighted
// regions"): exact geodesics (the ICH engine) inside each region of one weight, Steiner points
// only on the edges between regions. Each region becomes its own component of a union mesh,
// scaled by its weight so that lengths there are costs; a region's boundary points, placed as the
// bounded Steiner graph places them (weighted_field.h), carry costs from one region into the
// other, and a vertex's copies share theirs. Every cost is a real path's (never below the least
// cost) and at most the bounded graph's over the same boundary points, so within its
// (1 + epsilon); in a region of one weight the answers are exact. Private to core.

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"

namespace geodex {

// Whether the regions serve every product with `options`: direction-independent costs (no slope
// cost) whose passable faces all weigh the same (every weight 1 with impassable steep faces, one
// friction everywhere, or no weights). There are then no boundary points: every answer is exact,
// in a fraction of the graph's time.
bool RegionsServe(const WeightedOptions& options);
// Whether the finite entries of `weights` (face weights; +inf impassable) all have one value.
bool OneFiniteWeight(const std::vector<double>& weights);
// Whether a whole field with `options` is solved by regions: any weights without a slope cost.
// With several weights the answers keep the graph's bound and are never above it (the boundary
// points are the graph's; inside a region propagation is exact), in 2.7x the exact field's time
// on the target case (docs/performance.md). Times at points, matrices and paths use them too
// (TravelPointSolver, ComputeTravelPaths; a path is traced back through the boundary points).
bool RegionsServeFields(const WeightedOptions& options);
// Whether `options` has several weights and no slope cost: the regions answer, built around the
// query's own points, never a surface shared between queries (only one weight's is shared).
bool RegionsServeSeveralWeights(const WeightedOptions& options);

// The union mesh and its links for one mesh and one set of options (already validated), built
// once for many queries (a matrix's rows); immutable, CostsAt may run on many threads at once.
// `anchors`: the points searches will start or end at, when known (the boundary points are
// refined around those strictly inside faces or edges, as the graph is; other such points keep
// the bound once their paths are long against the edges around them).
class RegionSurface {
 public:
  static absl::StatusOr<std::shared_ptr<const RegionSurface>> Build(
      const TriangleMesh& mesh, const WeightedOptions& options,
      const std::vector<SurfacePoint>& anchors = {});
  ~RegionSurface();

  // Costs per file vertex from the nearest source (ComputeWeightedField's answer).
  absl::StatusOr<WeightedField> Field(const std::vector<SurfacePoint>& sources,
                                      const WeightedSurface::Limits& limits) const;
  // Costs at points. `whole`: targets covering the surface (no early stop).
  absl::StatusOr<WeightedCosts> CostsAt(const std::vector<SurfacePoint>& sources,
                                        const std::vector<SurfacePoint>& targets, bool whole,
                                        const WeightedSurface::Limits& limits) const;
  // Least-cost paths from `from`, one per target (+inf and no points when unreachable), named in
  // the surface's terms: the exact engine's paths on the union, mapped back.
  absl::StatusOr<std::vector<WeightedPath>> Paths(const SurfacePoint& from,
                                                  const std::vector<SurfacePoint>& tos,
                                                  const WeightedSurface::Limits& limits) const;
  uint64_t boundary_points() const;
  uint64_t bytes() const;  // the union mesh, its links and the point maps (for caches)
  // The weights it was built with (WeightedOptions::face_weight): a WeightedSurface OnRegions
  // compares against these rather than keep a copy.
  const std::vector<double>& face_weight() const;

  struct Impl;

 private:
  explicit RegionSurface(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The bounded placement's points on the edges between faces of different (finite) weights, with
// the graph refined around `anchors` (weighted/steiner_graph.cc): per such edge, the half-edge its
// parameters run along and its points. Errors: the Steiner-point limit, a bad anchor.
struct RegionBoundaryPoints {
  std::vector<uint32_t> half_edge;  // per chain
  std::vector<uint32_t> first;      // chain c: [first[c], first[c + 1])
  std::vector<double> param;
};
absl::StatusOr<RegionBoundaryPoints> PlaceRegionBoundaryPoints(
    const TriangleMesh& mesh, const WeightedOptions& options,
    const std::vector<SurfacePoint>& anchors);

}  // namespace geodex
