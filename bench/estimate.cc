// --estimate: the distance at random face points, the unfolding estimate on the exact field
// (section 4 of Xin & Wang 2010, its Table 1 / Fig. 6) against the exact value, the straight line
// and Dijkstra's method.

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

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "child_tasks.h"
#include "config.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/point_distance.h"
#include "geodex/surface_point.h"
#include "harness/machine.h"
#include "harness/stats.h"
#include "harness/table.h"
#include "measurements.h"
#include "meshes.h"
#include "sections.h"
#include "surface_points.h"

namespace geodex::bench {

const std::vector<std::string>& EstimateMeshes() {
  static const std::vector<std::string> names = {"gargoyle",  "armadillo", "fertility", "kitten",
                                                 "bunny-npm", "camelhead", "face"};
  return names;
}

// kEstimate: from file vertex job.sources[0], at job.count random face points: the exact distance
// (ComputeExactDistancesAt, job.batch points per call), the unfolding estimate on the exact field
// (EstimateDistanceAt), the straight line from the source, and Dijkstra's method (the Dijkstra
// field at the face's corners: min over them of d(v) + |v p|). Sends 4 doubles per point in that
// order.
void EstimateChild(const Job& job, const MeshData& data, const TriangleMesh& mesh,
                   ChildReport& report, std::vector<double>& values) {
  const uint32_t source_vertex = job.sources.at(0);
  const SurfacePoint source = SurfacePoint::AtVertex(source_vertex);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, {source});
  GeodesicOptions dijkstra_options;
  dijkstra_options.method = Method::kDijkstra;
  absl::StatusOr<DistanceField> dijkstra = ComputeDistanceField(mesh, {source}, dijkstra_options);
  if (!field.ok() || !dijkstra.ok()) {
    SetError(report, (field.ok() ? dijkstra.status() : field.status()).ToString());
    return;
  }
  report.solve_ms = field->stats.solve_ms;
  report.dijkstra_ms = dijkstra->stats.solve_ms;
  report.max_distance = LargestFinite(field->distance);
  PointSampler sampler(data, mesh, source_vertex, 0.0, job.seed);
  if (!sampler.ok()) {
    SetError(report, "no faces to sample");
    return;
  }
  std::vector<SurfacePoint> points;
  for (int i = 0; i < job.count; ++i) points.push_back(sampler.Next());

  std::vector<double> estimate(points.size(), kInf);
  auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < points.size(); ++i) {
    absl::StatusOr<PointEstimate> e = EstimateDistanceAt(mesh, *field, points[i]);
    if (!e.ok()) {
      SetError(report, e.status().ToString());
      return;
    }
    estimate[i] = e->distance;
  }
  report.estimate_ms = MsSince(start);

  std::vector<double> exact;
  start = std::chrono::steady_clock::now();
  for (size_t begin = 0; begin < points.size(); begin += static_cast<size_t>(job.batch)) {
    const size_t end = std::min(points.size(), begin + static_cast<size_t>(job.batch));
    const std::vector<SurfacePoint> batch(points.begin() + begin, points.begin() + end);
    absl::StatusOr<std::vector<std::pair<double, uint32_t>>> d =
        ComputeExactDistancesAt(mesh, {source}, batch);
    if (!d.ok()) {
      SetError(report, d.status().ToString());
      return;
    }
    for (const auto& [distance, label] : *d) exact.push_back(distance);
    ++report.exact_solves;
  }
  report.exact_ms = MsSince(start);

  const std::array<double, 3> s = FilePosition(data, source_vertex);
  for (size_t i = 0; i < points.size(); ++i) {
    const std::array<double, 3> p = PointPosition(data, points[i]);
    double via_dijkstra = kInf;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = data.faces[3 * points[i].face + k];
      via_dijkstra =
          std::min(via_dijkstra, dijkstra->distance[v] + Distance3(FilePosition(data, v), p));
    }
    values.insert(values.end(), {exact[i], estimate[i], Distance3(s, p), via_dijkstra});
  }
}

std::vector<Section> RunEstimate(const Config& config, const std::vector<MeshInfo>& meshes) {
  Section s{"Distance at a surface point: the unfolding estimate (section 4, Table 1 / Fig. 6)",
            absl::StrFormat(
                "From vertex 0 to %d random face points per mesh (seed %d; uniform over the "
                "area). Relative error |d - d_exact| / d_exact of: the straight line from the "
                "source (Euclidean), Dijkstra's method (the Dijkstra field at the face's corners, "
                "min of d(v) + |v p|) and the estimate (EstimateDistanceAt on the exact field: "
                "the paper's unfolding). d_exact from ComputeExactDistancesAt, %d points per "
                "call. med / p90 / max over the points; <= 0.1%% = the share of points where "
                "the estimate is within 0.1%%, below = the share where it is below d_exact. "
                "est us = per point (the field computed once: field ms); exact ms = per call.",
                config.points, config.seed, config.batch),
            Table({"mesh", "faces", "points", "line med", "line p90", "line max", "Dijkstra med",
                   "Dijkstra p90", "Dijkstra max", "estimate med", "estimate p90", "estimate max",
                   "estimate <= 0.1%", "estimate <= 0.01%", "estimate below", "field ms", "est us",
                   "exact ms", "other load"},
                  "lrr"),
            {}};
  for (const MeshInfo* mesh : ModeMeshes(config, meshes, EstimateMeshes())) {
    std::fprintf(stderr, "estimate: %s, %d points\n", mesh->name.c_str(), config.points);
    Job job;
    job.task = Task::kEstimate;
    job.sources = {mesh->sources.at(0)};
    job.seed = config.seed;
    job.count = config.points;
    job.batch = config.batch;
    const Outcome o = RunPointJob(*mesh, job, config);
    Progress("estimate vs exact", o);
    if (!o.ok() || o.distance.size() != 4 * static_cast<size_t>(config.points)) {
      s.table.AddRow({mesh->name, Count(mesh->report.faces), Count(config.points), o.StatusText()});
      if (!o.message.empty()) s.notes.push_back(absl::StrCat(mesh->name, ": ", o.message));
      continue;
    }
    std::vector<double> line, dijkstra, estimate;
    int within_01 = 0, within_001 = 0, below = 0, skipped = 0, inconsistent = 0;
    double worst = -1, worst_exact = 0;
    for (size_t i = 0; i < o.distance.size(); i += 4) {
      const double exact = o.distance[i];
      if (!(exact > 0) || !std::isfinite(exact)) {
        ++skipped;
        continue;
      }
      const double e = RelDiff(o.distance[i + 1], exact);
      // The straight line is a lower bound and Dijkstra's method (a real path) an upper bound.
      if (o.distance[i + 2] > exact * (1 + 1e-12) || o.distance[i + 3] < exact * (1 - 1e-12)) {
        ++inconsistent;
      }
      line.push_back(RelDiff(o.distance[i + 2], exact));
      dijkstra.push_back(RelDiff(o.distance[i + 3], exact));
      estimate.push_back(e);
      within_01 += e <= 1e-3;
      within_001 += e <= 1e-4;
      below += o.distance[i + 1] < exact * (1 - 1e-12);
      if (e > worst) {
        worst = e;
        worst_exact = exact;
      }
    }
    const double n = static_cast<double>(estimate.size());
    const ChildReport& c = o.report;
    s.table.AddRow({mesh->name, Count(mesh->report.faces), Count(estimate.size()),
                    Percent(Median(line)), Percent(Quantile(line, 0.9)), Percent(MaxOf(line)),
                    Percent(Median(dijkstra)), Percent(Quantile(dijkstra, 0.9)),
                    Percent(MaxOf(dijkstra)), Percent(Median(estimate)),
                    Percent(Quantile(estimate, 0.9)), Percent(MaxOf(estimate)),
                    Percent(within_01 / n), Percent(within_001 / n), Percent(below / n),
                    Ms(c.solve_ms), absl::StrFormat("%.2f", 1000 * c.estimate_ms / n),
                    Ms(c.exact_ms / std::max(1, c.exact_solves)), OtherLoad(o)});
    s.notes.push_back(absl::StrFormat(
        "%s: the worst estimate is off by %s at a point %s of D = %.6g from the source%s",
        mesh->name, Percent(worst), Percent(worst_exact / c.max_distance), c.max_distance,
        skipped > 0 ? absl::StrCat(" (", skipped, " points at distance 0 or unreachable skipped)")
                    : ""));
    if (inconsistent > 0) {
      s.notes.push_back(absl::StrFormat(
          "%s: at %d points the exact value is not between the straight line and Dijkstra's "
          "method: not exact there",
          mesh->name, inconsistent));
    }
  }
  return {s};
}

}  // namespace geodex::bench
