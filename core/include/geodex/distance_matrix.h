#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

// Exact distances between N sources and M targets (any surface points), row-major
// (values[i * cols + j] = d(sources[i], targets[j]); +inf where unreachable). One solve per
// distinct source, each stopping as soon as every target's distance is final, instead of N*M
// point-to-point queries.
struct DistanceMatrix {
  size_t rows = 0, cols = 0;
  std::vector<double> values;
  SolveStats stats;  // summed over the solves (solve_ms: total)
  // geodexd's answers only (the client library): how far each point given as a 3D position
  // (SurfacePoint::kPosition) moved onto the surface, the sources' then the targets'; 0 for a point
  // given on the surface. Core's own queries take surface points and leave it empty.
  std::vector<double> snap_distances;
};

// The k_nearest rule of a matrix row: the k smallest of `row[0..n)` keep their values (ties: the
// lower index), every other entry becomes +inf. No-op when k is 0 or at least n.
void KeepKNearest(uint32_t k, double* row, size_t n);

struct MatrixOptions {
  // Per row: lambda, max_distance (entries beyond it are +inf and each row stops there), the
  // window budget (per row) and the cancel token (stops every row).
  GeodesicOptions solver;
  // > 0: per source only its k nearest targets get their exact distance (ties: the lower target
  // index), the rest +inf, and each row stops as soon as those k are final.
  uint32_t k_nearest = 0;
  // Rows solved at once: 0 = every core this process may run on (sched_getaffinity).
  unsigned threads = 0;
  // Runs a helper on another thread (a server's compute pool: queued behind other calls' work, so
  // a large matrix takes a fair share, not every worker). Empty: std::thread. The calling thread
  // always solves rows too, so a helper that starts late (or never) only costs parallelism; it
  // may also start after the call returned, and then does nothing.
  std::function<void(std::function<void()>)> spawn;
  // Called after each solved row with (rows done, rows to solve), one call at a time, from any of
  // the threads. For progress bars; keep it cheap.
  std::function<void(size_t, size_t)> on_row;
  // Called with each output row (its index into `sources` and its targets.size() values) as soon
  // as it and every row before it are final: in order 0, 1, ..., one call at a time, from any of
  // the threads. For streaming rows as they finish; the returned matrix holds the same values.
  // A symmetric row is final once every row before it in the sweep is solved too (they solve its
  // other pairs).
  std::function<void(size_t row, const double* values)> on_final_row;
};

// Rows (one targeted solve per distinct source) run in parallel. When sources and targets are the
// same points (the planner's case) each pair is solved once and d(i, j) = d(j, i) bit for bit:
// row i solves only targets j > i, d(i, i) = 0. Every entry equals the distance
// ComputeShortestPath gives for that pair (exact, up to round-off) whatever the matrix's size or
// order.
absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const MatrixOptions& options);
absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const GeodesicOptions& options = {});

// The same, asked whole: what `geodex matrix` and ComputeDistanceMatrix ask. The CLI hands it to
// either backend as it is and proto/convert carries it (api::MatrixQueryToProto: the points,
// solver and k_nearest; threads and callbacks stay on the asking side).
struct MatrixQuery {
  std::vector<SurfacePoint> sources, targets;
  MatrixOptions options;
};
absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const MatrixQuery& query);

// The number of cores this process may run on (at least 1).
unsigned UsableCores();

// A question about surface points, asked whole: the exact distance at each of `points` from the
// nearest of `sources`. What `geodex distances --at` and EstimateDistances' exact mode ask; the CLI
// hands it to either backend as it is, and proto/convert maps it to the wire and back, so a new
// member here reaches every caller without touching the layers between.
struct PointQuery {
  std::vector<SurfacePoint> sources, points;
  GeodesicOptions options;
  // Also each point's geodesic direction: what a robot at the point follows towards the nearest
  // source (the direction field of ComputeDirectionField, at any surface point).
  bool directions = false;
  // The points cover the surface (a raster's cells on a TIN): the whole field is solved, without
  // A* towards them or the early stop, whose bookkeeping costs O(points) whenever one improves.
  // A travel cost's graph is then refined around the sources only, not every cell
  // (WeightedSurface::Limits::anchor_targets).
  bool covers_surface = false;
};
// Its answer, one entry per point, in order.
struct PointValues {
  std::vector<double> distance;  // kUnreachable where no source reaches
  std::vector<uint32_t> source;  // the nearest source's index, kNoIndex where unreachable
  // With query.directions: the unit tangent (file coordinates) of the point's shortest path
  // towards its nearest source, its first step as traced; 0 0 0 at a source, NaN where
  // unreachable. Where several shortest paths meet (the cut locus), the traced one's.
  std::vector<std::array<double, 3>> direction;
  SolveStats stats;
};
// One multi-source solve that stops once every point's distance is final.
absl::StatusOr<PointValues> ComputePointValues(const TriangleMesh& mesh, const PointQuery& query);

// ComputePointValues as (distance, source) pairs; `stats`, when given, receives the counters.
absl::StatusOr<std::vector<std::pair<double, uint32_t>>> ComputeExactDistancesAt(
    const TriangleMesh& mesh, const std::vector<SurfacePoint>& sources,
    const std::vector<SurfacePoint>& points, const GeodesicOptions& options = {},
    SolveStats* stats = nullptr);

}  // namespace geodex
