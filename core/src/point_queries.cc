// Queries answered by targeted solves: single source / single target paths (paper section 5),
// distance matrices and exact distances at surface points.

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "absl/strings/str_format.h"
#include "geodex/distance_matrix.h"
#include "geodex/shortest_path.h"
#include "ich/ich_solver.h"
#include "mesh_lookup.h"
#include "path_trace.h"
#include "source_resolver.h"
#include "travel_queries.h"

namespace geodex {
namespace {

// The internal vertices a surface point lies on or in (a split vertex's copies too).
std::vector<uint32_t> TouchedVertices(const TriangleMesh& mesh, const SurfacePoint& p) {
  std::vector<uint32_t> out;
  auto vertex = [&](uint32_t v) {
    if (v >= mesh.file_vertex_count()) return;
    out.push_back(v);
    for (uint32_t u = mesh.file_vertex_count(); u < mesh.vertex_count(); ++u) {
      if (mesh.FileVertex(u) == v) out.push_back(u);
    }
  };
  switch (p.kind) {
    case SurfacePoint::Kind::kVertex:
      vertex(p.vertex);
      break;
    case SurfacePoint::Kind::kEdge:
      vertex(p.edge_from);
      vertex(p.edge_to);
      break;
    case SurfacePoint::Kind::kFace:
      if (p.face < mesh.face_count()) {
        for (int k = 0; k < 3; ++k) out.push_back(mesh.FaceVertex(p.face, k));
      }
      break;
    default:
      break;
  }
  return out;
}

}  // namespace

std::string UnreachableReason(const TriangleMesh& mesh, const SurfacePoint& from,
                              const SurfacePoint& to, double max_distance) {
  const std::vector<uint32_t> at_to = TouchedVertices(mesh, to),
                              at_from = TouchedVertices(mesh, from);
  if (to.kind == SurfacePoint::Kind::kVertex && !at_to.empty() &&
      std::all_of(at_to.begin(), at_to.end(), [&](uint32_t v) { return mesh.IsIsolated(v); })) {
    return "it is a vertex no face uses";
  }
  bool shared = false;
  for (uint32_t a : at_to) {
    for (uint32_t b : at_from) shared |= mesh.Component(a) == mesh.Component(b);
  }
  if (!shared && !at_to.empty() && !at_from.empty()) {
    return absl::StrFormat(
        "it is on another part of the surface (a barrier, a hole or a gap parts them; the mesh has "
        "%d parts)",
        mesh.report().components);
  }
  if (std::isfinite(max_distance))
    return absl::StrFormat("it is farther than the max_distance limit (%.6g)", max_distance);
  return "no path reaches it";
}

namespace {

absl::Status CheckOptions(const GeodesicOptions& options) {
  if (!IsExactMethod(options.method)) {
    return absl::InvalidArgumentError(
        "point queries and paths need an exact method (exact or ich)");
  }
  return ValidateGeodesicOptions(options);
}

absl::StatusOr<std::vector<ich::ResolvedSource>> ResolveSources(
    const TriangleMesh& mesh, const std::vector<SurfacePoint>& points) {
  if (points.empty()) return absl::InvalidArgumentError("no sources given");
  SourceResolver resolver(mesh);
  for (uint32_t i = 0; i < points.size(); ++i) {
    if (absl::Status s = resolver.Add(points[i], i); !s.ok()) return s;
  }
  return resolver.sources();
}

absl::StatusOr<ich::ResolvedTarget> ResolveTarget(const TriangleMesh& mesh, const SurfacePoint& p) {
  SourceResolver resolver(mesh);
  if (absl::Status s = resolver.Add(p, 0); !s.ok()) return s;
  ich::ResolvedTarget t;
  for (const ich::ResolvedSource& r : resolver.sources()) {
    if (r.is_vertex) {
      t.vertices.push_back(r.vertex);
    } else {
      t.placements.push_back({r.face, r.px, r.py});
    }
  }
  if (!t.vertices.empty()) {
    const double* q = mesh.positions() + 3 * t.vertices.front();
    std::copy(q, q + 3, t.position);
  } else {
    const auto& pl = t.placements.front();
    FacePointPosition(mesh, pl.face, pl.px, pl.py, t.position);
  }
  return t;
}

absl::StatusOr<std::vector<ich::ResolvedTarget>> ResolveTargets(
    const TriangleMesh& mesh, const std::vector<SurfacePoint>& points) {
  std::vector<ich::ResolvedTarget> out;
  for (const SurfacePoint& p : points) {
    absl::StatusOr<ich::ResolvedTarget> t = ResolveTarget(mesh, p);
    if (!t.ok()) return t.status();
    out.push_back(*std::move(t));
  }
  return out;
}

}  // namespace

void AddSolveStats(const SolveStats& s, SolveStats* total) {
  total->windows_created += s.windows_created;
  total->windows_filtered_at_creation += s.windows_filtered_at_creation;
  total->windows_filtered_at_pop += s.windows_filtered_at_pop;
  total->windows_processed += s.windows_processed;
  total->pseudo_sources += s.pseudo_sources;
  total->max_level = std::max(total->max_level, s.max_level);
  total->peak_live_windows = std::max(total->peak_live_windows, s.peak_live_windows);
  total->peak_bytes = std::max(total->peak_bytes, s.peak_bytes);
  total->solve_ms += s.solve_ms;
}

absl::StatusOr<PathsQueryResult> ComputeShortestPaths(const TriangleMesh& mesh,
                                                      const SurfacePoint& from,
                                                      const std::vector<SurfacePoint>& tos,
                                                      const PathQueryOptions& options) {
  if (absl::Status s = CheckOptions(options.solver); !s.ok()) return s;
  if (tos.empty()) return absl::InvalidArgumentError("paths need at least one target");
  if (options.solver.travel.has_value()) return ComputeTravelPaths(mesh, from, tos, options.solver);
  absl::StatusOr<std::vector<ich::ResolvedSource>> sources = ResolveSources(mesh, {from});
  if (!sources.ok()) return sources.status();
  absl::StatusOr<std::vector<ich::ResolvedTarget>> targets = ResolveTargets(mesh, tos);
  if (!targets.ok()) return targets.status();
  ich::IchSolver solver(mesh, options.solver);
  std::vector<ich::TargetResult> results;
  PathsQueryResult out;
  const bool early = !options.full_field;
  if (absl::Status s = solver.SolveForTargets(*sources, *targets, options.use_heuristic && early,
                                              early, &results, &out.stats);
      !s.ok()) {
    return s;
  }
  const VertexPaths paths{solver.distances().data(), solver.origins().data()};
  out.distance.assign(tos.size(), kUnreachable);
  out.paths.resize(tos.size());
  for (size_t i = 0; i < tos.size(); ++i) {
    absl::StatusOr<GeodesicPath> path = TraceFromTarget(mesh, paths, results[i], tos[i]);
    if (absl::IsNotFound(path.status())) continue;  // unreachable: inf, no points
    if (!path.ok()) return path.status();
    // The trace runs from the target back to the source: report it from `from` to `to`.
    std::reverse(path->points.begin(), path->points.end());
    if (from.kind != SurfacePoint::Kind::kVertex) path->points.front().where = from;
    out.distance[i] = results[i].distance;
    out.paths[i] = *std::move(path);
  }
  return out;
}

absl::StatusOr<PathQueryResult> ComputeShortestPath(const TriangleMesh& mesh,
                                                    const SurfacePoint& from,
                                                    const SurfacePoint& to,
                                                    const PathQueryOptions& options) {
  absl::StatusOr<PathsQueryResult> paths = ComputeShortestPaths(mesh, from, {to}, options);
  if (!paths.ok()) return paths.status();
  if (paths->distance[0] == kUnreachable) {
    return absl::NotFoundError(absl::StrFormat(
        "%s is unreachable from %s: %s", SurfacePointToString(to), SurfacePointToString(from),
        UnreachableReason(mesh, from, to, options.solver.max_distance)));
  }
  PathQueryResult result;
  result.distance = paths->distance[0];
  result.path = std::move(paths->paths[0]);
  result.stats = paths->stats;
  return result;
}

absl::StatusOr<PathQueryResult> ComputeShortestPath(const TriangleMesh& mesh,
                                                    const PathQuery& query) {
  return ComputeShortestPath(mesh, query.from, query.to, query.options);
}

void KeepKNearest(uint32_t k, double* row, size_t n) {
  if (k == 0 || k >= n) return;
  std::vector<size_t> order(n);
  for (size_t j = 0; j < n; ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(),
                   [row](size_t a, size_t b) { return row[a] < row[b]; });
  for (size_t j = k; j < n; ++j) row[order[j]] = kUnreachable;
}

unsigned UsableCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return static_cast<unsigned>(n);
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// Row indices handed out to the calling thread and its helpers. Shared, so a helper that starts
// after the call returned finds nothing left and touches nothing else.
struct RowQueue {
  std::atomic<size_t> next{0};
  size_t total = 0;
  std::function<void(size_t)> run;  // valid while the call waits; only reached for rows < total
  std::mutex mu;
  std::condition_variable done_cv;
  size_t done = 0;  // guarded by mu
};

void WorkRows(const std::shared_ptr<RowQueue>& q) {
  for (;;) {
    const size_t i = q->next.fetch_add(1);
    if (i >= q->total) return;
    q->run(i);
    std::lock_guard<std::mutex> lock(q->mu);
    if (++q->done == q->total) q->done_cv.notify_all();
  }
}

// Runs run(0..total-1) on the calling thread and up to threads - 1 helpers; returns when all ran.
void RunRows(size_t total, unsigned threads,
             const std::function<void(std::function<void()>)>& spawn,
             std::function<void(size_t)> run) {
  auto q = std::make_shared<RowQueue>();
  q->total = total;
  q->run = std::move(run);
  const size_t helpers = std::min<size_t>(threads > 0 ? threads - 1 : 0, total > 0 ? total - 1 : 0);
  std::vector<std::thread> own;
  for (size_t h = 0; h < helpers; ++h) {
    if (spawn) {
      spawn([q] { WorkRows(q); });
    } else {
      own.emplace_back([q] { WorkRows(q); });
    }
  }
  WorkRows(q);
  {
    std::unique_lock<std::mutex> lock(q->mu);
    q->done_cv.wait(lock, [&] { return q->done == q->total; });
  }
  for (std::thread& t : own) t.join();
}

}  // namespace

absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const MatrixQuery& query) {
  return ComputeDistanceMatrix(mesh, query.sources, query.targets, query.options);
}

absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const GeodesicOptions& options) {
  MatrixOptions m;
  m.solver = options;
  return ComputeDistanceMatrix(mesh, sources, targets, m);
}

absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const MatrixOptions& options) {
  if (absl::Status s = CheckOptions(options.solver); !s.ok()) return s;
  if (sources.empty() || targets.empty()) {
    return absl::InvalidArgumentError("a distance matrix needs at least one source and one target");
  }
  // Distinct points: a point given twice is solved once (and a symmetric matrix stays symmetric).
  std::vector<std::string> source_keys, target_keys;
  for (const SurfacePoint& p : sources) source_keys.push_back(SurfacePointToString(p));
  for (const SurfacePoint& p : targets) target_keys.push_back(SurfacePointToString(p));
  // A slope-dependent speed's times differ by direction: row to column, every pair solved.
  const bool directional =
      options.solver.travel.has_value() && IsDirectional(*options.solver.travel);
  const bool symmetric = options.k_nearest == 0 && source_keys == target_keys && !directional;
  std::vector<size_t> source_row(sources.size());  // source -> its distinct row
  std::vector<size_t> distinct;                    // distinct row -> first source index
  {
    std::map<std::string, size_t> seen;
    for (size_t i = 0; i < sources.size(); ++i) {
      auto [it, fresh] = seen.emplace(source_keys[i], distinct.size());
      if (fresh) distinct.push_back(i);
      source_row[i] = it->second;
    }
  }
  // Columns solved: every target, or (symmetric) the distinct points.
  std::vector<size_t> column_of(targets.size());  // target -> solved column
  std::vector<SurfacePoint> solved_targets;
  if (symmetric) {
    for (size_t j = 0; j < targets.size(); ++j) column_of[j] = source_row[j];
    for (size_t r : distinct) solved_targets.push_back(targets[r]);
  } else {
    for (size_t j = 0; j < targets.size(); ++j) column_of[j] = j;
    solved_targets = targets;
  }
  absl::StatusOr<std::vector<ich::ResolvedTarget>> resolved = ResolveTargets(mesh, solved_targets);
  if (!resolved.ok()) return resolved.status();
  std::vector<std::vector<ich::ResolvedSource>> row_sources(distinct.size());
  for (size_t r = 0; r < distinct.size(); ++r) {
    absl::StatusOr<std::vector<ich::ResolvedSource>> src =
        ResolveSources(mesh, {sources[distinct[r]]});
    if (!src.ok()) return src.status();
    row_sources[r] = *std::move(src);
  }

  const size_t rows = distinct.size(), cols = solved_targets.size();
  // Symmetric: pair (r, c) is solved by whichever of the two comes first in a sweep along the
  // points' longest extent, so later rows need only targets on one side of them, close together
  // (a small A* ball).
  std::vector<size_t> rank(rows), order(rows);
  for (size_t r = 0; r < rows; ++r) order[r] = r;
  if (symmetric) {
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = hi[k] = (*resolved)[0].position[k];
    for (const ich::ResolvedTarget& t : *resolved) {
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], t.position[k]);
        hi[k] = std::max(hi[k], t.position[k]);
      }
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k) {
      if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    }
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return (*resolved)[a].position[axis] < (*resolved)[b].position[axis];
    });
    for (size_t n = 0; n < rows; ++n) rank[order[n]] = n;
  }
  std::vector<double> solved(rows * cols, kUnreachable);
  SolveStats total_stats;
  absl::Status first_error = absl::OkStatus();
  std::atomic<bool> failed{false};
  std::mutex mu;  // guards total_stats, first_error, rows_done, on_row and the rows_final state
  size_t rows_done = 0;
  // d(r, c) once rows r and (symmetric) c are solved: the sweep's earlier point solved the pair.
  auto cell = [&](size_t r, size_t c) {
    return symmetric && rank[c] < rank[r] ? solved[c * cols + r] : solved[r * cols + c];
  };
  // on_final_row's state: which rows are solved, how many rows at the start of the solve order
  // are (a symmetric row is final once it and every row before it in the sweep are), and the
  // next output row to hand out.
  std::vector<char> row_solved(options.on_final_row ? rows : 0, 0);
  size_t solved_prefix = 0, next_final = 0;
  std::vector<double> final_row(options.on_final_row ? targets.size() : 0);
  auto hand_out_final_rows = [&](size_t r) {  // with mu held, after row r was solved
    row_solved[r] = 1;
    while (solved_prefix < rows && row_solved[order[solved_prefix]]) ++solved_prefix;
    for (; next_final < sources.size(); ++next_final) {
      const size_t row = source_row[next_final];
      if (symmetric ? solved_prefix <= rank[row] : !row_solved[row]) break;
      for (size_t j = 0; j < targets.size(); ++j) final_row[j] = cell(row, column_of[j]);
      options.on_final_row(next_final, final_row.data());
    }
  };
  const uint32_t k = options.k_nearest;
  // A travel cost: one weighted graph for every row.
  std::optional<TravelPointSolver> travel;
  if (options.solver.travel.has_value()) {
    // The rows' distinct points grade the graph (a repeated source must not count twice toward
    // the graded placement's cap on sources).
    std::vector<SurfacePoint> row_points;
    for (size_t r : distinct) row_points.push_back(sources[r]);
    absl::StatusOr<TravelPointSolver> solver =
        TravelPointSolver::Create(mesh, options.solver, row_points, solved_targets);
    if (!solver.ok()) return solver.status();
    travel.emplace(*std::move(solver));
  }
  auto solve_row = [&](size_t r) {
    if (failed.load(std::memory_order_relaxed)) return;
    // Symmetric: row r needs only the columns after it in the sweep; d(r, r) = 0.
    std::vector<size_t> columns;
    std::vector<ich::ResolvedTarget> subset;
    const std::vector<ich::ResolvedTarget>* row_targets = &*resolved;
    if (symmetric) {
      for (size_t c = 0; c < cols; ++c) {
        if (rank[c] > rank[r]) {
          columns.push_back(c);
          subset.push_back((*resolved)[c]);
        }
      }
      row_targets = &subset;
    } else {
      for (size_t c = 0; c < cols; ++c) columns.push_back(c);
    }
    absl::Status status = absl::OkStatus();
    SolveStats stats;
    if (!columns.empty() && options.solver.travel.has_value()) {
      // Travel times from the weighted engine (row to column; the symmetric sweep only when they
      // are direction-independent).
      std::vector<SurfacePoint> points;
      for (size_t c : columns) points.push_back(solved_targets[c]);
      absl::StatusOr<PointValues> values = travel->Solve({sources[distinct[r]]}, points);
      status = values.status();
      if (values.ok()) {
        double* row = &solved[r * cols];
        for (size_t j = 0; j < columns.size(); ++j) row[columns[j]] = values->distance[j];
        KeepKNearest(k, row, cols);
        stats = values->stats;
      }
    } else if (!columns.empty()) {
      std::vector<ich::TargetResult> results;
      try {
        ich::IchSolver solver(mesh, options.solver);
        solver.set_final_needed(k);
        status = solver.SolveForTargets(row_sources[r], *row_targets, /*use_heuristic=*/true, true,
                                        &results, &stats);
      } catch (const std::bad_alloc&) {
        status = absl::ResourceExhaustedError(
            "out of memory for geodesic windows; set a window budget, a max_distance or lambda > "
            "0");
      }
      if (status.ok()) {
        double* row = &solved[r * cols];
        for (size_t j = 0; j < results.size(); ++j) row[columns[j]] = results[j].distance;
        // Only the k nearest are exact (k > 0 is never symmetric: columns are every target).
        KeepKNearest(k, row, cols);
      }
    }
    if (symmetric) solved[r * cols + r] = 0;
    std::lock_guard<std::mutex> lock(mu);
    if (!status.ok()) {
      if (first_error.ok()) first_error = status;
      failed.store(true, std::memory_order_relaxed);
      return;
    }
    AddSolveStats(stats, &total_stats);
    ++rows_done;
    if (options.on_final_row) hand_out_final_rows(r);
    if (options.on_row) options.on_row(rows_done, rows);
  };
  const unsigned threads = options.threads > 0 ? options.threads : UsableCores();
  // Symmetric rows go in sweep order: the largest rows first (they solve the most pairs), and
  // rows become final (on_final_row) steadily rather than all at the end.
  RunRows(rows, threads, options.spawn, [&](size_t n) { solve_row(order[n]); });
  if (!first_error.ok()) return first_error;
  DistanceMatrix m;
  m.rows = sources.size();
  m.cols = targets.size();
  m.values.resize(m.rows * m.cols);
  for (size_t i = 0; i < m.rows; ++i) {
    for (size_t j = 0; j < m.cols; ++j)
      m.values[i * m.cols + j] = cell(source_row[i], column_of[j]);
  }
  m.stats = total_stats;
  return m;
}

absl::StatusOr<PointValues> ComputePointValues(const TriangleMesh& mesh, const PointQuery& query) {
  if (absl::Status s = CheckOptions(query.options); !s.ok()) return s;
  if (query.options.travel.has_value()) return ComputeTravelPointValues(mesh, query);
  absl::StatusOr<std::vector<ich::ResolvedSource>> src = ResolveSources(mesh, query.sources);
  if (!src.ok()) return src.status();
  absl::StatusOr<std::vector<ich::ResolvedTarget>> resolved = ResolveTargets(mesh, query.points);
  if (!resolved.ok()) return resolved.status();
  std::vector<ich::TargetResult> results;
  PointValues out;
  // One targeted solve (A* towards the points when they are close together), stopping once every
  // point is final; the solver stays for the directions (read off its per-vertex origins).
  ich::IchSolver solver(mesh, query.options);
  const bool targeted = !query.covers_surface;
  if (absl::Status s =
          solver.SolveForTargets(*src, *resolved, targeted, targeted, &results, &out.stats);
      !s.ok()) {
    return s;
  }
  for (const ich::TargetResult& r : results) {
    out.distance.push_back(r.distance);
    out.source.push_back(r.label);
  }
  if (query.directions) {
    const VertexPaths paths{solver.distances().data(), solver.origins().data()};
    for (const ich::TargetResult& r : results) {
      out.direction.push_back(TargetDirection(mesh, paths, r));
    }
  }
  return out;
}

absl::StatusOr<std::vector<std::pair<double, uint32_t>>> ComputeExactDistancesAt(
    const TriangleMesh& mesh, const std::vector<SurfacePoint>& sources,
    const std::vector<SurfacePoint>& points, const GeodesicOptions& options,
    SolveStats* stats_out) {
  absl::StatusOr<PointValues> values = ComputePointValues(mesh, {sources, points, options});
  if (!values.ok()) return values.status();
  std::vector<std::pair<double, uint32_t>> out;
  for (size_t i = 0; i < values->distance.size(); ++i) {
    out.push_back({values->distance[i], values->source[i]});
  }
  if (stats_out != nullptr) *stats_out = values->stats;
  return out;
}

}  // namespace geodex
