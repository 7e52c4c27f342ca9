#pragma once

// Weighted ("travel cost") shortest paths: least costs on a triangle mesh whose faces carry
// weights (friction), within a stated factor (1 + epsilon) of the true least cost, by the Steiner
// point method.
//
// Cost: a straight piece inside face f costs its 3D length x w(f); a piece along an edge shared by
// two faces costs its length x the smaller of their weights. A face of weight +inf is impassable
// (its edges stay usable when a passable face borders them). Times = cost / speed are the caller's.
//
// Method (Aleksandrov, Lanthier, Maheshwari, Sack, SWAT 1998 / Aleksandrov, Maheshwari, Sack,
// JACM 52(1) 2005, with the Steiner points on the EDGES as in the former and the geometric
// progression of the latter):
//  * per vertex v (passable, non-degenerate faces around v only): d(v) = the smallest height of
//    those faces from v (a lower bound of the distance from v to the boundary of its star),
//    w_min(v), w_max(v) their smallest and largest weight, and the vicinity radius
//        r(v) = (epsilon / 8) * d(v) * w_min(v) / w_max(v);
//  * per edge e = ab of length L (same faces): theta(e) = the smallest corner angle at a or b in
//    the faces beside e (capped at 90 degrees) and lambda(e) = 1 + sqrt(epsilon / 2) sin theta(e);
//  * Steiner points on e at distances r(a) lambda^i (i = 0, 1, ...) from a while below L / 2, the
//    same from b, and the midpoint. Per edge that is
//        k(e) = 1 + sum over its ends v of ceil(ln(L / (2 r(v))) / ln lambda(e))
//             ~ (2 / sin theta) sqrt(2 / epsilon) ln(4 L w_max / (epsilon d w_min)),
//    i.e. O(log(1/epsilon) / sqrt(epsilon)) per edge (about 55 at epsilon 0.1 and 260 at 0.01 on
//    a grid of right isosceles triangles);
//  * the graph: the vertices and Steiner points; within a face, every node on one edge to every
//    node on the other two edges (cost = segment length x w(f)); along an edge, consecutive nodes
//    (cost x the edge's weight). Face edges are never stored: they are generated when a node is
//    settled, so memory grows with the number of points, not with k^2 per face;
//  * Dijkstra with an indexed binary heap over flat arrays (decrease-key, ties by node id, so runs
//    are bit-for-bit deterministic). A source or target on a face or an edge joins the graph with
//    edges to every node on its face(s) (and the straight segment when source and target share a
//    face or an edge).
//
// The bound. Every cost is the cost of an actual path on the surface (a polyline through the
// nodes), so it is never below the true least cost. Above: cost <= (1 + epsilon) x the least cost
// is the AMS bound for their placement; the argument carried over to edge points is, in sketch:
// take an optimal path, (1) reroute each stretch of it inside the vicinity ball B(v) of radius
// r(v) through v: it adds <= 2 r(v) w_max(v), and the path spends at least weighted
// (d(v) - r(v)) w_min(v) on each side of the stretch inside v's star, with every point of the path
// in at most 4 stars: total <= (epsilon / 4) x the cost; (2) snap every other crossing point x (at
// distance t >= r(v) from its nearer end v) to its nearest Steiner point: the move is
// <= t (lambda - 1) / 2 <= sqrt(epsilon / 8) t sin theta, both pieces at x are >= t sin theta
// long, the optimal path is stationary in each crossing point (Snell's law), so first-order
// changes cancel and the second-order change is <= about (epsilon / 2) x the pieces' cost.
// Sources and targets strictly inside faces or edges have neither long pieces nor a vicinity ball
// of their own (AMS make them vertices): two such points a hair from an edge, facing each other
// across it, would cost the detour through the nearest Steiner point, unboundedly more than their
// distance. So the graph is refined around them (weighted/steiner_graph.cc, AddAnchorPoints: each
// crossing near the point gets a node within sqrt(epsilon / 8) x its distance from the point, and
// the vertices of the point's faces continue their progressions down to (epsilon / 8) x the
// point's distance from them), which restores both steps for them; it adds some hundreds of
// points per such point (logarithmic in how close it lies to an edge or a vertex). What is NOT
// proved here: (2)'s stationarity next to a stretch rerouted by (1). The tests measure the bound
// on planes (against Euclidean and Snell's-law optima, and between points 1e-6 from an edge or a
// corner) and on real meshes (against the exact engine) and find the error far inside epsilon
// (typically < epsilon / 10).
//
// Memory: 8 bytes per Steiner point for its position on its edge plus, during a solve, 20 bytes
// per node (cost, label, parent, heap slot) and 4 per heap entry: about 32 bytes per Steiner point,
// bounded by WeightedOptions::max_steiner_points. A search that stops at its targets (paths,
// costs at points) writes a node's state only once the wave reaches its edge, so it touches the
// memory of the part of the surface it searches. Time: settling a node relaxes the nodes of the
// other edges of its faces, O(k) each, O(k^2) per face in total.

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/cancel.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// A direction-dependent cost (slope-dependent speed, docs/travel.md): the cost per 3D metre of a
// straight piece as a function of the sine of its slope angle along the direction of travel
// (rise / 3D length, -1 straight down to +1 straight up), sampled uniformly on [-1, 1] and
// linearly interpolated; +inf where a direction cannot be walked. A face's weight multiplies it.
//
// Switchbacks: inside each face the cost of a direction is the lower convex envelope of that
// polar cost (Rowe and Ross 1990): where zigzagging between two directions is cheaper than going
// straight, the straight piece costs the zigzag. The engine builds the envelope per face (the
// convex hull of the unit-cost set, sampled every half degree), so a face's cost does not depend
// on how it is cut. Costs then differ by direction: fields are costs from the sources outward
// unless WeightedOptions::inbound. No (1 + epsilon) bound is proved for such costs, so their
// search trades the graph's "a real path" for accuracy: ceil(1 / epsilon) - 1 evenly spaced
// points per edge, and the wave also crosses an edge between two settled neighbouring points
// (its cost linear along the segment: an ordered-upwind step), which makes the error fall about
// as the spacing squared; a cost may then fall slightly below the least cost.
struct SlopeCost {
  std::vector<double> per_metre;  // >= 2 samples; > 0 or +inf; finite at sine 0 (the level)
};

struct WeightedOptions {
  // The stated bound: every cost is at most (1 + epsilon) x the true least cost and never below
  // it. Must be in (0, 1). With a slope cost, the Steiner points' spacing instead (SlopeCost).
  double epsilon = 0.01;
  // One weight per FILE face: > 0 and finite, or +inf (impassable). Empty: every face weighs 1.
  std::vector<double> face_weight;
  // Nodes costlier than this stay +inf; the search stops there. Must be > 0.
  double max_distance = std::numeric_limits<double>::infinity();
  // 0 = unlimited; otherwise a solve needing more Steiner points fails with
  // LimitExceededError(Limit::kSteinerPoints) before allocating them.
  uint64_t max_steiner_points = 0;
  // The work budget, 0 = unlimited; otherwise, where the exact engine answers (the regions:
  // weighted_regions.h), a solve creating more windows fails as GeodesicOptions::max_windows says
  // (Limit::kWindows), and a graph's search relaxing more than kGraphLinksPerWindow links a
  // window (geodex/limits.h) fails the same way, so every solve's time is bounded.
  uint64_t max_windows = 0;
  const CancelToken* cancel = nullptr;  // polled every few thousand settled nodes
  // Null: direction-independent (cost = length x weight, the bound above holds). Shared, so
  // copying options does not copy the samples.
  std::shared_ptr<const SlopeCost> slope_cost;
  // With a slope cost: costs of reaching the sources (a walker ends there) rather than of leaving
  // them. A path from `from` to `to` is always walked from `from`.
  bool inbound = false;
  // A self-check for tests (it costs a second pass over every graph edge): after a whole search,
  // every edge's far node must cost no more than its near node plus the link (the search settled
  // the graph's least costs); otherwise the solve fails with an Internal error.
  bool check_optimality = false;
};

// Checks epsilon, max_distance, the weights (their count against the mesh's faces) and the slope
// cost's samples. Errors are InvalidArgument naming the option (InvalidOptionOf: "epsilon",
// "max_distance", "face_weight", "face_weight[7]", "slope_cost").
absl::Status ValidateWeightedOptions(const TriangleMesh& mesh, const WeightedOptions& options);

struct WeightedStats {
  uint64_t nodes_settled = 0;
  uint64_t edge_relaxations = 0;  // graph edges evaluated (generated on the fly)
  uint64_t peak_bytes = 0;        // Steiner positions + per-node state + heap
  double solve_ms = 0;
};

struct WeightedField {
  std::vector<double> cost;      // per FILE vertex; +inf where unreachable (or beyond max_distance)
  std::vector<uint32_t> source;  // index into the sources; 0xffffffff where unreachable
  uint64_t steiner_points = 0;
  uint64_t graph_edges = 0;  // edges of the (implicit) graph
  double epsilon = 0;
  WeightedStats stats;
};

// Least costs from every vertex to the nearest of `sources` (vertex, edge or face points).
// Errors: InvalidArgument (options, an empty source list, a bad source), ResourceExhausted
// (LimitExceededError kSteinerPoints), Cancelled.
absl::StatusOr<WeightedField> ComputeWeightedField(const TriangleMesh& mesh,
                                                   const std::vector<SurfacePoint>& sources,
                                                   const WeightedOptions& options);

struct WeightedCosts {
  std::vector<double> cost;      // per target; +inf when unreachable
  std::vector<uint32_t> source;  // per target; 0xffffffff when unreachable
  uint64_t steiner_points = 0;
  WeightedStats stats;
};

// Least costs at arbitrary surface points (vertex, edge or face points). The search stops once
// every target is final. Errors: as ComputeWeightedField.
absl::StatusOr<WeightedCosts> ComputeWeightedCostsAt(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const WeightedOptions& options);

struct WeightedPath;
class RegionSurface;  // core/src/weighted_regions.h

// The weighted engine's graph (Steiner points) and cost model (the per-face switchback ranges of
// a slope cost) for one mesh and one set of options, built once for many queries: a matrix's
// rows. Immutable once built; CostsAt may run on many threads at once. `mesh` must outlive it.
class WeightedSurface {
 public:
  // `seeds`: the sources the surface will be searched from, when known (a slope cost's points are
  // then denser near them, for the small times there; docs/engine.md). `anchors`: other points it
  // will be searched to (targets). Under the bound, the graph is refined around every seed and
  // anchor strictly inside a face or an edge (the bound's argument needs it there); CostsAt and
  // Paths given any other such point build a surface refined around it for that call (they answer
  // within the bound either way, the shared surface just saves the build for vertices and its
  // anchors). Errors: as ComputeWeightedField (options, a bad seed or anchor, the Steiner-point
  // limit).
  static absl::StatusOr<WeightedSurface> Build(const TriangleMesh& mesh,
                                               const WeightedOptions& options,
                                               const std::vector<SurfacePoint>& seeds = {},
                                               const std::vector<SurfacePoint>& anchors = {});
  // The surface of one weight, answered by the exact engine (core's RegionSurface: every passable
  // face weighs the same, so no Steiner point is needed), wrapped to be shared and cached as a
  // graph is (BuildTravelSurface): CostsAt and Paths answer from it, steiner_points() is 0.
  static WeightedSurface OnRegions(const TriangleMesh& mesh, WeightedOptions options,
                                   std::shared_ptr<const RegionSurface> regions);
  WeightedSurface(WeightedSurface&&) noexcept;
  WeightedSurface& operator=(WeightedSurface&&) noexcept;
  ~WeightedSurface();

  // ComputeWeightedCostsAt on this surface, with the options it was built with. The search stops
  // once every target is final, unless `whole` (targets covering the surface: the early stop's
  // bookkeeping would cost more than it saves); the answers are the same either way.
  absl::StatusOr<WeightedCosts> CostsAt(const std::vector<SurfacePoint>& sources,
                                        const std::vector<SurfacePoint>& targets,
                                        bool whole = false) const;

  // What one query on a surface shared by many obeys (CostsAt above takes them from the options
  // the surface was built with): max_distance in cost units (> 0) and the call's cancel token.
  struct Limits {
    double max_distance = std::numeric_limits<double>::infinity();
    const CancelToken* cancel = nullptr;
    // False for targets that cover the surface (a raster's cells on a TIN, up to millions): the
    // graph is then refined around the sources only, as before the anchors, since refining it
    // around every cell would add hundreds of points each. Such a target's time keeps the bound
    // once its path is long against the edges around it (a few edge lengths at epsilon 0.01); a
    // cell a hair from an edge and next to a source may exceed it.
    bool anchor_targets = true;
  };
  absl::StatusOr<WeightedCosts> CostsAt(const std::vector<SurfacePoint>& sources,
                                        const std::vector<SurfacePoint>& targets, bool whole,
                                        const Limits& limits) const;
  // ComputeWeightedPaths on this surface. InvalidArgument naming "inbound" for a slope cost's
  // surface built inbound (a path is walked from its start).
  absl::StatusOr<std::vector<WeightedPath>> Paths(const SurfacePoint& from,
                                                  const std::vector<SurfacePoint>& tos,
                                                  const Limits& limits) const;

  // Whether a solve with `options` on `mesh` would build this very surface, so a query may use
  // it instead of building its own: the same mesh object, epsilon and weights, within the
  // options' Steiner-point limit, and no slope cost on either (its points follow each query's
  // sources), and for a surface OnRegions the same window budget (max_windows). Costs the
  // comparison of the weights.
  bool Serves(const TriangleMesh& mesh, const WeightedOptions& options) const;

  uint64_t steiner_points() const;
  uint64_t bytes() const;  // what it holds: the Steiner points, the graph's arrays, the weights
  const TriangleMesh& mesh() const;  // the mesh it was built on

  struct Impl;  // the graph and cost model (weighted/surface.cc); every solve builds one

 private:
  explicit WeightedSurface(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct WeightedPath {
  double cost = 0;
  // points.front() is `from`, points.back() is `to`; straight inside each face, bending only on
  // edges and at vertices (at Steiner points and vertices).
  std::vector<PathPoint> points;
  uint64_t steiner_points = 0;
  WeightedStats stats;
};

// The least-cost path between two surface points (the search stops once `to` is final).
// Errors: as ComputeWeightedField, and NotFound when `to` cannot be reached.
absl::StatusOr<WeightedPath> ComputeWeightedPath(const TriangleMesh& mesh, const SurfacePoint& from,
                                                 const SurfacePoint& to,
                                                 const WeightedOptions& options);

// One least-cost path per target from `from`, on one graph with one search (it stops once every
// target is final); an unreachable target (or one beyond max_distance) has cost +inf and no
// points. Each path's stats are the whole call's.
absl::StatusOr<std::vector<WeightedPath>> ComputeWeightedPaths(const TriangleMesh& mesh,
                                                               const SurfacePoint& from,
                                                               const std::vector<SurfacePoint>& tos,
                                                               const WeightedOptions& options);

// The weighted engine's options for `options` (which carry a travel cost): the weights with every
// face steeper than max_slope_deg made +inf, epsilon, max_distance in engine units (seconds /
// seconds per unit), the slope cost of a slope-dependent speed, inbound, the Steiner-point limit
// and the cancel token. Errors: InvalidArgument naming "travel" for what the weighted engine does
// not do (lambda > 0, Dijkstra).
absl::StatusOr<WeightedOptions> WeightedOptionsFor(const TriangleMesh& mesh,
                                                   const GeodesicOptions& options);

}  // namespace geodex
