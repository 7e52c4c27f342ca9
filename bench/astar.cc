// --astar: exact paths from vertex 0 to random target points, A* (section 5 of Xin & Wang 2010)
// against solving the whole field, grouped by the target's distance (the shape of its Table 2).

#include <malloc.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "child_tasks.h"
#include "config.h"
#include "geodex/distance_field.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "harness/machine.h"
#include "harness/peak_memory.h"
#include "harness/stats.h"
#include "harness/table.h"
#include "measurements.h"
#include "meshes.h"
#include "sections.h"
#include "surface_points.h"

namespace geodex::bench {
namespace {

// --astar's groups: the target's distance as a fraction of the source's largest distance, in
// (0, 10%], (10%, 25%], (25%, 50%], (50%, 100%] (a face point a little beyond the farthest vertex
// counts in the last group).
constexpr int kGroups = 4;
constexpr double kGroupLimit[kGroups] = {0.10, 0.25, 0.50, 1.00};
constexpr const char* kGroupName[kGroups] = {"<= 10%", "10-25%", "25-50%", "50-100%"};

int GroupOf(double fraction) {
  for (int g = 0; g < kGroups; ++g) {
    if (fraction <= kGroupLimit[g]) return g;
  }
  return kGroups - 1;
}

// One --astar pair as the parent sees it.
struct PairResult {
  SurfacePoint target;
  Outcome outcome;
  double fraction = 0;  // the exact (full-field) distance / the source's largest distance
  int group = 0;
  double full_ms = 0, astar_ms = 0;
  double speedup = 0;   // full_ms / astar_ms
  double rel_diff = 0;  // |A* - full| / full
};

}  // namespace

const std::vector<std::string>& AstarMeshes() {
  static const std::vector<std::string> names = {"gargoyle", "armadillo"};
  return names;
}

// kPlanTargets: the whole field from job.sources[0] gives the largest distance D; random points
// (job.vertex_share of them vertices) are drawn and put into their group by the estimated
// distance (EstimateDistanceAt; exact at vertices) until every group has job.count points. The
// points go back group by group in turn (0, 1, 2, 3, 0, 1, ...), so that a slow drift of the
// machine's speed touches every group alike.
void PlanTargetsChild(const Job& job, const MeshData& data, const TriangleMesh& mesh,
                      ChildReport& report, std::vector<double>& values) {
  const uint32_t source = job.sources.at(0);
  absl::StatusOr<DistanceField> field =
      ComputeDistanceField(mesh, {SurfacePoint::AtVertex(source)});
  if (!field.ok()) {
    SetError(report, field.status().ToString());
    return;
  }
  report.max_distance = LargestFinite(field->distance);
  report.solve_ms = field->stats.solve_ms;
  PointSampler sampler(data, mesh, source, job.vertex_share, job.seed);
  if (!sampler.ok() || !(report.max_distance > 0)) {
    SetError(report, "no points to sample around the source");
    return;
  }
  const size_t wanted = static_cast<size_t>(job.count);
  std::array<std::vector<SurfacePoint>, kGroups> groups;
  auto short_of_points = [&] {
    for (const auto& g : groups) {
      if (g.size() < wanted) return true;
    }
    return false;
  };
  constexpr uint64_t kMaxDraws = 20'000'000;
  while (short_of_points() && report.candidates < kMaxDraws) {
    const SurfacePoint p = sampler.Next();
    ++report.candidates;
    absl::StatusOr<PointEstimate> e = EstimateDistanceAt(mesh, *field, p);
    if (!e.ok() || !std::isfinite(e->distance)) continue;
    const double fraction = e->distance / report.max_distance;
    if (!(fraction > 1e-9)) continue;  // the source itself
    std::vector<SurfacePoint>& group = groups[GroupOf(fraction)];
    if (group.size() < wanted) group.push_back(p);
  }
  for (size_t i = 0; i < wanted; ++i) {
    for (const auto& g : groups) {
      if (i < g.size()) PackPoint(g[i], &values);
    }
  }
}

// kPathPair: from[0] -> to[0], first A* (the default PathQueryOptions) `repeat` times, then the
// full field (full_field = true: solve everything, then trace) `repeat` times, after one untimed
// A* run. Times are the medians of the whole ComputeShortestPath call (wall) and of
// SolveStats.solve_ms. Before each of the two series, freed memory goes back to the system
// (malloc_trim) and the RSS high-water mark is reset, so each peak is the series' own.
void PathPairChild(const Job& job, const TriangleMesh& mesh, ChildReport& report) {
  auto run = [&](const PathQueryOptions& options, double* wall_ms, double* solve_ms,
                 SolveStats* stats, double* distance) {
    std::vector<double> wall, solve;
    for (int r = 0; r < job.repeat; ++r) {
      const auto start = std::chrono::steady_clock::now();
      absl::StatusOr<PathQueryResult> result =
          ComputeShortestPath(mesh, job.from.at(0), job.to.at(0), options);
      wall.push_back(MsSince(start));
      if (!result.ok()) {
        SetError(report, result.status().ToString());
        report.resource_exhausted = absl::IsResourceExhausted(result.status());
        return false;
      }
      solve.push_back(result->stats.solve_ms);
      *stats = result->stats;
      *distance = result->distance;
    }
    *wall_ms = Median(wall);
    *solve_ms = Median(solve);
    return true;
  };
  PathQueryOptions astar;  // the defaults: A*, stop at the target
  // One untimed A* run first, so that neither run's RSS pays for paging in the solver's code.
  if (absl::StatusOr<PathQueryResult> warm =
          ComputeShortestPath(mesh, job.from.at(0), job.to.at(0), astar);
      !warm.ok()) {
    SetError(report, warm.status().ToString());
    return;
  }
  malloc_trim(0);
  const int64_t before_astar_kb = CurrentRssKb();
  if (!ResetRssHighWater()) report.hiwater_reset = 0;
  if (!run(astar, &report.wall_ms, &report.solve_ms, &report.stats, &report.astar_distance)) {
    return;
  }
  report.astar_peak_kb = PeakRssKb() - before_astar_kb;
  malloc_trim(0);
  const int64_t before_full_kb = CurrentRssKb();
  if (!ResetRssHighWater()) report.hiwater_reset = 0;
  PathQueryOptions full;
  full.full_field = true;
  if (!run(full, &report.full_wall_ms, &report.full_solve_ms, &report.full_stats,
           &report.full_distance)) {
    return;
  }
  report.full_peak_kb = PeakRssKb() - before_full_kb;
  report.runs = job.repeat;
}

std::vector<Section> RunAstar(const Config& config, const std::vector<MeshInfo>& meshes) {
  Section groups{
      "Exact paths: A* vs the full field (section 5, the shape of Table 2)",
      absl::StrFormat(
          "From vertex 0 to random target points (seed %d; a quarter vertices, the rest face "
          "points uniform over the area), %d per group, grouped by the target's exact distance as "
          "a fraction of the source's largest vertex distance D. Each pair runs in its own child: "
          "ComputeShortestPath with the default options (A*: stop at the target) R times, then "
          "with full_field = true (solve the whole field, then trace) R times. ms = median of "
          "the whole call over the repeats; per group the median over its pairs. speedup = "
          "median of the per-pair full ms / A* ms, min = the smallest; worst A*/full = the "
          "largest per-pair A* ms / full ms (below 1: never slower). windows = windows created; "
          "ratio = median of per-pair full / A*. peak MiB = SolveStats.peak_bytes, delta RSS = "
          "the child's RSS high-water mark over its resident size before the run (medians). max "
          "rel diff = max |d_A* - d_full| / d_full.",
          config.seed, config.per_group),
      Table({"mesh", "faces", "d / D", "pairs", "vertex targets", "full ms", "A* ms", "speedup",
             "min speedup", "worst A*/full", "full windows", "A* windows", "windows ratio",
             "full peak MiB", "A* peak MiB", "full delta RSS MiB", "A* delta RSS MiB",
             "max rel diff"},
            "lrl"),
      {}};
  Section pairs{"Exact paths: every pair",
                "Per pair: the target (v: vertex, f: face point), its exact distance d and d / D; "
                "ms of the whole call and SolveStats.solve_ms (medians of R); A* peak MiB = "
                "SolveStats.peak_bytes of the A* run.",
                Table({"mesh", "pair", "target", "d", "d / D", "full ms", "A* ms", "full solve ms",
                       "A* solve ms", "speedup", "full windows", "A* windows", "A* peak MiB",
                       "A* delta RSS MiB", "rel diff", "other load"},
                      "lrl"),
                {}};
  bool first = true;
  for (const MeshInfo* mesh : ModeMeshes(config, meshes, AstarMeshes())) {
    const int repeat = RepeatFor(config, *mesh);
    const uint32_t source = mesh->sources.at(0);
    std::fprintf(stderr, "astar: %s, source %u, R = %d\n", mesh->name.c_str(), source, repeat);
    Job plan_job;
    plan_job.task = Task::kPlanTargets;
    plan_job.sources = {source};
    plan_job.seed = config.seed;
    plan_job.count = config.per_group;
    const Outcome plan = RunPointJob(*mesh, plan_job, config);
    Progress("choose the targets", plan);
    if (!plan.ok()) {
      groups.notes.push_back(absl::StrCat(
          mesh->name, ": choosing the targets failed: ", plan.StatusText(), " ", plan.message));
      continue;
    }
    const double largest = plan.report.max_distance;
    const std::vector<SurfacePoint> targets = UnpackPoints(plan.distance);
    std::vector<PairResult> results;
    for (size_t i = 0; i < targets.size(); ++i) {
      Job job;
      job.task = Task::kPathPair;
      job.from = {SurfacePoint::AtVertex(source)};
      job.to = {targets[i]};
      job.repeat = repeat;
      PairResult r;
      r.target = targets[i];
      r.outcome = RunPointJob(*mesh, job, config);
      const ChildReport& c = r.outcome.report;
      Progress(absl::StrFormat("pair %d/%d (%s): A* %.1f ms, full %.1f ms", i + 1, targets.size(),
                               ShortPoint(targets[i]), c.wall_ms, c.full_wall_ms),
               r.outcome);
      if (r.outcome.ok()) {
        r.fraction = c.full_distance / largest;
        r.group = GroupOf(r.fraction);
        r.full_ms = c.full_wall_ms;
        r.astar_ms = c.wall_ms;
        r.speedup = r.full_ms / r.astar_ms;
        r.rel_diff = RelDiff(c.astar_distance, c.full_distance);
      } else {
        groups.notes.push_back(absl::StrCat(mesh->name, " target ",
                                            SurfacePointToString(targets[i]), ": ",
                                            r.outcome.StatusText(), " ", r.outcome.message));
      }
      results.push_back(std::move(r));
    }

    // Per group, then all pairs (group index kGroups).
    for (int g = 0; g <= kGroups; ++g) {
      std::vector<double> full_ms, astar_ms, speedup, worst, full_windows, astar_windows,
          windows_ratio, full_peak, astar_peak, full_rss, astar_rss, rel_diff;
      int vertex_targets = 0;
      for (const PairResult& r : results) {
        if (!r.outcome.ok() || (g < kGroups && r.group != g)) continue;
        const ChildReport& c = r.outcome.report;
        vertex_targets += r.target.kind == SurfacePoint::Kind::kVertex;
        full_ms.push_back(r.full_ms);
        astar_ms.push_back(r.astar_ms);
        speedup.push_back(r.speedup);
        worst.push_back(r.astar_ms / r.full_ms);
        full_windows.push_back(static_cast<double>(c.full_stats.windows_created));
        astar_windows.push_back(static_cast<double>(c.stats.windows_created));
        windows_ratio.push_back(static_cast<double>(c.full_stats.windows_created) /
                                std::max<double>(1, static_cast<double>(c.stats.windows_created)));
        full_peak.push_back(static_cast<double>(c.full_stats.peak_bytes));
        astar_peak.push_back(static_cast<double>(c.stats.peak_bytes));
        full_rss.push_back(static_cast<double>(c.full_peak_kb));
        astar_rss.push_back(static_cast<double>(c.astar_peak_kb));
        rel_diff.push_back(r.rel_diff);
      }
      if (full_ms.empty()) continue;
      groups.table.AddRow(
          {mesh->name, Count(mesh->report.faces), g < kGroups ? kGroupName[g] : "all",
           Count(full_ms.size()), Count(vertex_targets), Ms(Median(full_ms)), Ms(Median(astar_ms)),
           Ratio(Median(speedup)), Ratio(MinOf(speedup)), absl::StrFormat("%.3f", MaxOf(worst)),
           Count(static_cast<uint64_t>(Median(full_windows))),
           Count(static_cast<uint64_t>(Median(astar_windows))), Ratio(Median(windows_ratio)),
           MiBOfBytes(Median(full_peak)), MiBOfBytes(Median(astar_peak)),
           MiBOfKb(static_cast<int64_t>(Median(full_rss))),
           MiBOfKb(static_cast<int64_t>(Median(astar_rss))), Sci(MaxOf(rel_diff))});
    }
    if (!first) groups.table.AddBreak();
    first = false;

    // The targets of the task, stated as measured.
    std::vector<double> near_speedup, worst_all, rel_all;
    int slower = 0, near_below_10 = 0;
    for (const PairResult& r : results) {
      if (!r.outcome.ok()) continue;
      worst_all.push_back(r.astar_ms / r.full_ms);
      rel_all.push_back(r.rel_diff);
      if (r.astar_ms > r.full_ms) ++slower;
      if (r.fraction <= 0.25) {
        near_speedup.push_back(r.speedup);
        if (r.speedup < 10) ++near_below_10;
      }
    }
    groups.notes.push_back(absl::StrFormat(
        "%s: D = %.6g; %d targets from %d random points; within 25%%: %d pairs, A* speedup "
        "%s-%s (median %s), %d below 10x; all pairs: worst A*/full %.3f, %d pairs where A* was "
        "slower; max rel diff of the distances %s",
        mesh->name, largest, targets.size(), plan.report.candidates, near_speedup.size(),
        Ratio(MinOf(near_speedup)), Ratio(MaxOf(near_speedup)), Ratio(Median(near_speedup)),
        near_below_10, MaxOf(worst_all), slower, Sci(MaxOf(rel_all))));
    for (size_t i = 0; i < results.size(); ++i) {
      const PairResult& r = results[i];
      const ChildReport& c = r.outcome.report;
      std::vector<std::string> cells = {mesh->name, Count(i + 1), ShortPoint(r.target)};
      if (!r.outcome.ok()) {
        cells.push_back(r.outcome.StatusText());
      } else {
        cells.insert(cells.end(),
                     {absl::StrFormat("%.6g", c.full_distance), Percent(r.fraction), Ms(r.full_ms),
                      Ms(r.astar_ms), Ms(c.full_solve_ms), Ms(c.solve_ms), Ratio(r.speedup),
                      Count(c.full_stats.windows_created), Count(c.stats.windows_created),
                      MiBOfBytes(static_cast<double>(c.stats.peak_bytes)), MiBOfKb(c.astar_peak_kb),
                      Sci(r.rel_diff), OtherLoad(r.outcome)});
      }
      pairs.table.AddRow(cells);
    }
    pairs.table.AddBreak();
  }
  return {groups, pairs};
}

}  // namespace geodex::bench
