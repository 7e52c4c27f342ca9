// Queries answered by targeted solves: single source / single target paths (paper section 5),
// distance matrices and exact distances at surface points.

#include <algorithm>
#include <map>
#include <string>

#include "absl/strings/str_format.h"
#include "geodex/distance_matrix.h"
#include "geodex/shortest_path.h"
#include "ich/ich_solver.h"
#include "mesh_lookup.h"
#include "path_trace.h"
#include "source_resolver.h"

namespace geodex {
namespace {

absl::Status CheckOptions(const GeodesicOptions& options) {
  if (!IsExactMethod(options.method)) {
    return absl::InvalidArgumentError("point queries and paths need an exact method (exact or ich)");
  }
  return ValidateSolveOptions(options);
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

// One targeted solve without the heuristic, stopping once every target is final.
absl::Status SolveUntilTargetsFinal(const TriangleMesh& mesh, const GeodesicOptions& options,
                                    const std::vector<ich::ResolvedSource>& sources,
                                    const std::vector<ich::ResolvedTarget>& targets,
                                    std::vector<ich::TargetResult>* results, SolveStats* stats) {
  ich::IchSolver solver(mesh, options);
  return solver.SolveForTargets(sources, targets, false, true, results, stats);
}

void AddStats(const SolveStats& s, SolveStats* total) {
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

}  // namespace

absl::StatusOr<PathQueryResult> ComputeShortestPath(const TriangleMesh& mesh,
                                                    const SurfacePoint& from,
                                                    const SurfacePoint& to,
                                                    const PathQueryOptions& options) {
  if (absl::Status s = CheckOptions(options.solver); !s.ok()) return s;
  absl::StatusOr<std::vector<ich::ResolvedSource>> sources = ResolveSources(mesh, {from});
  if (!sources.ok()) return sources.status();
  absl::StatusOr<ich::ResolvedTarget> target = ResolveTarget(mesh, to);
  if (!target.ok()) return target.status();
  const std::vector<ich::ResolvedTarget> targets = {*std::move(target)};
  ich::IchSolver solver(mesh, options.solver);
  std::vector<ich::TargetResult> results;
  SolveStats stats;
  const bool early = !options.full_field;
  if (absl::Status s = solver.SolveForTargets(*sources, targets, options.use_heuristic && early,
                                              early, &results, &stats);
      !s.ok()) {
    return s;
  }
  absl::StatusOr<GeodesicPath> path = TraceFromTarget(
      mesh, VertexPaths{solver.distances().data(), solver.origins().data()}, results[0], to);
  if (!path.ok()) {
    if (path.status().code() == absl::StatusCode::kNotFound) {
      return absl::NotFoundError(absl::StrFormat("%s is unreachable from %s",
                                                 SurfacePointToString(to),
                                                 SurfacePointToString(from)));
    }
    return path.status();
  }
  // The trace runs from the target back to the source: report it from `from` to `to`.
  std::reverse(path->points.begin(), path->points.end());
  if (from.kind != SurfacePoint::Kind::kVertex) path->points.front().where = from;
  PathQueryResult result;
  result.distance = results[0].distance;
  result.path = *std::move(path);
  result.stats = stats;
  return result;
}

absl::StatusOr<DistanceMatrix> ComputeDistanceMatrix(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const GeodesicOptions& options) {
  if (absl::Status s = CheckOptions(options); !s.ok()) return s;
  if (sources.empty() || targets.empty()) {
    return absl::InvalidArgumentError("a distance matrix needs at least one source and one target");
  }
  absl::StatusOr<std::vector<ich::ResolvedTarget>> resolved = ResolveTargets(mesh, targets);
  if (!resolved.ok()) return resolved.status();
  DistanceMatrix m;
  m.rows = sources.size();
  m.cols = targets.size();
  m.values.assign(m.rows * m.cols, kUnreachable);
  std::map<std::string, size_t> solved;  // a source given twice is solved once
  for (size_t i = 0; i < sources.size(); ++i) {
    const std::string key = SurfacePointToString(sources[i]);
    if (auto it = solved.find(key); it != solved.end()) {
      std::copy_n(m.values.begin() + it->second * m.cols, m.cols, m.values.begin() + i * m.cols);
      continue;
    }
    absl::StatusOr<std::vector<ich::ResolvedSource>> src = ResolveSources(mesh, {sources[i]});
    if (!src.ok()) return src.status();
    std::vector<ich::TargetResult> results;
    SolveStats stats;
    if (absl::Status s = SolveUntilTargetsFinal(mesh, options, *src, *resolved, &results, &stats);
        !s.ok()) {
      return s;
    }
    for (size_t j = 0; j < m.cols; ++j) m.values[i * m.cols + j] = results[j].distance;
    AddStats(stats, &m.stats);
    solved.emplace(key, i);
  }
  return m;
}

absl::StatusOr<std::vector<std::pair<double, uint32_t>>> ComputeExactDistancesAt(
    const TriangleMesh& mesh, const std::vector<SurfacePoint>& sources,
    const std::vector<SurfacePoint>& points, const GeodesicOptions& options,
    SolveStats* stats_out) {
  if (absl::Status s = CheckOptions(options); !s.ok()) return s;
  absl::StatusOr<std::vector<ich::ResolvedSource>> src = ResolveSources(mesh, sources);
  if (!src.ok()) return src.status();
  absl::StatusOr<std::vector<ich::ResolvedTarget>> resolved = ResolveTargets(mesh, points);
  if (!resolved.ok()) return resolved.status();
  std::vector<ich::TargetResult> results;
  SolveStats stats;
  if (absl::Status s = SolveUntilTargetsFinal(mesh, options, *src, *resolved, &results, &stats);
      !s.ok()) {
    return s;
  }
  std::vector<std::pair<double, uint32_t>> out;
  for (const ich::TargetResult& r : results) out.push_back({r.distance, r.label});
  if (stats_out != nullptr) *stats_out = stats;
  return out;
}

}  // namespace geodex
