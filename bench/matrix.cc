// --matrix: a 16 x 16 distance matrix between random points against 16 full fields and 256 A*
// queries (section 5 of Xin & Wang 2010: many sources, many targets).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "child_tasks.h"
#include "config.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "harness/machine.h"
#include "harness/stats.h"
#include "harness/table.h"
#include "measurements.h"
#include "meshes.h"
#include "sections.h"
#include "surface_points.h"

namespace geodex::bench {
namespace {

// Adds one solve's stats to *total: windows and times summed, peaks the largest.
void AddUp(const SolveStats& s, SolveStats* total) {
  total->windows_created += s.windows_created;
  total->windows_processed += s.windows_processed;
  total->max_level = std::max(total->max_level, s.max_level);
  total->peak_live_windows = std::max(total->peak_live_windows, s.peak_live_windows);
  total->peak_bytes = std::max(total->peak_bytes, s.peak_bytes);
  total->solve_ms += s.solve_ms;
}

}  // namespace

const std::vector<std::string>& MatrixMeshes() {
  static const std::vector<std::string> names = {"armadillo"};
  return names;
}

// kSamplePoints: job.count random points around job.sources[0].
void SamplePointsChild(const Job& job, const MeshData& data, const TriangleMesh& mesh,
                       ChildReport& report, std::vector<double>& values) {
  PointSampler sampler(data, mesh, job.sources.at(0), job.vertex_share, job.seed);
  if (!sampler.ok()) {
    SetError(report, "no points to sample");
    return;
  }
  for (int i = 0; i < job.count; ++i) PackPoint(sampler.Next(), &values);
}

// kMatrix, kFields, kPathQueries: the three ways to get the distances between job.from and
// job.to, `repeat` times each; wall_ms / solve_ms are the medians of the totals, stats the last
// repeat's (windows summed over the solves, peaks the largest). kMatrix sends the matrix back;
// kPathQueries the distances, then each query's median wall ms.
void MatrixChild(const Job& job, const TriangleMesh& mesh, ChildReport& report,
                 std::vector<double>& values) {
  const size_t rows = job.from.size(), cols = job.to.size();
  std::vector<double> wall, solve;
  std::vector<std::vector<double>> query_ms(rows * cols);
  for (int r = 0; r < job.repeat; ++r) {
    SolveStats total;
    const auto start = std::chrono::steady_clock::now();
    if (job.task == Task::kMatrix) {
      absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(mesh, job.from, job.to);
      if (!m.ok()) {
        SetError(report, m.status().ToString());
        return;
      }
      total = m->stats;
      values = m->values;
    } else if (job.task == Task::kFields) {
      for (const SurfacePoint& s : job.from) {
        absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, {s});
        if (!field.ok()) {
          SetError(report, field.status().ToString());
          return;
        }
        AddUp(field->stats, &total);
      }
    } else {
      values.assign(rows * cols, kInf);
      for (size_t i = 0; i < rows; ++i) {
        for (size_t j = 0; j < cols; ++j) {
          const auto query_start = std::chrono::steady_clock::now();
          absl::StatusOr<PathQueryResult> q = ComputeShortestPath(mesh, job.from[i], job.to[j]);
          query_ms[i * cols + j].push_back(MsSince(query_start));
          if (!q.ok()) {
            SetError(report, absl::StrCat("pair ", i, ", ", j, ": ", q.status().ToString()));
            return;
          }
          values[i * cols + j] = q->distance;
          AddUp(q->stats, &total);
        }
      }
    }
    wall.push_back(MsSince(start));
    solve.push_back(total.solve_ms);
    report.stats = total;
  }
  report.runs = job.repeat;
  report.wall_ms = Median(wall);
  report.solve_ms = Median(solve);
  if (job.task == Task::kPathQueries) {
    for (const auto& ms : query_ms) values.push_back(Median(ms));
  }
}

std::vector<Section> RunMatrix(const Config& config, const std::vector<MeshInfo>& meshes) {
  constexpr int kSide = 16;
  Section s{"Distance matrix: 16 x 16 vs 16 full fields vs 256 A* queries",
            absl::StrFormat(
                "16 random source points and 16 random target points (seed %d; a quarter "
                "vertices, the rest face points uniform over the area). Each row is one child: "
                "ComputeDistanceMatrix(sources, targets) (one solve per source, stopping once "
                "all 16 targets are final); ComputeDistanceField once per source (the cost of 16 "
                "full fields; on their own they give no exact values at face points); "
                "ComputeShortestPath (A*) for each of the 256 pairs. ms = median over R of the "
                "total wall time; solve ms = the summed SolveStats.solve_ms. x matrix = ms / the "
                "matrix's ms. windows = created, summed over the solves. peak MiB = the largest "
                "SolveStats.peak_bytes of one solve; delta RSS = the child's peak RSS over the "
                "mesh-only baseline. vs matrix = max |d - d_matrix| / d_matrix over the 256 "
                "pairs.",
                config.seed),
            Table({"mesh", "faces", "method", "solves", "R", "ms", "solve ms", "ms per solve",
                   "x matrix", "windows", "peak MiB", "delta RSS MiB", "vs matrix", "other load"},
                  "lrl"),
            {}};
  for (const MeshInfo* mesh : ModeMeshes(config, meshes, MatrixMeshes())) {
    const int repeat = RepeatFor(config, *mesh);
    const int query_repeat = config.repeat > 0 ? config.repeat : 1;
    std::fprintf(stderr, "matrix: %s, R = %d (queries R = %d)\n", mesh->name.c_str(), repeat,
                 query_repeat);
    Job sample;
    sample.task = Task::kSamplePoints;
    sample.sources = {mesh->sources.at(0)};
    sample.seed = config.seed;
    sample.count = 2 * kSide;
    const Outcome points = RunPointJob(*mesh, sample, config);
    const std::vector<SurfacePoint> all = UnpackPoints(points.distance);
    if (!points.ok() || all.size() != 2 * kSide) {
      s.notes.push_back(absl::StrCat(
          mesh->name, ": sampling the points failed: ", points.StatusText(), " ", points.message));
      continue;
    }
    Job job;
    job.from.assign(all.begin(), all.begin() + kSide);
    job.to.assign(all.begin() + kSide, all.end());
    job.repeat = repeat;
    job.task = Task::kMatrix;
    const Outcome matrix = RunPointJob(*mesh, job, config);
    Progress("distance matrix", matrix);
    job.task = Task::kFields;
    const Outcome fields = RunPointJob(*mesh, job, config);
    Progress("16 full fields", fields);
    job.task = Task::kPathQueries;
    job.repeat = query_repeat;
    const Outcome queries = RunPointJob(*mesh, job, config);
    Progress("256 A* queries", queries);

    const size_t cells = static_cast<size_t>(kSide) * kSide;
    const double matrix_ms = matrix.ok() ? matrix.report.wall_ms : std::nan("");
    double query_rel = std::nan("");
    if (matrix.ok() && queries.ok() && matrix.distance.size() == cells &&
        queries.distance.size() == 2 * cells) {
      query_rel = 0;
      for (size_t k = 0; k < cells; ++k) {
        query_rel = std::max(query_rel, RelDiff(queries.distance[k], matrix.distance[k]));
      }
    }
    auto row = [&](const std::string& method, const Outcome& o, int solves, int r,
                   const std::string& vs) {
      std::vector<std::string> out = {mesh->name, Count(mesh->report.faces), method, Count(solves),
                                      Count(r)};
      if (!o.ok()) {
        out.push_back(o.StatusText());
        if (!o.message.empty())
          s.notes.push_back(absl::StrCat(mesh->name, " ", method, ": ", o.message));
        return out;
      }
      const ChildReport& c = o.report;
      out.insert(out.end(),
                 {Ms(c.wall_ms), Ms(c.solve_ms), Ms(c.wall_ms / solves),
                  absl::StrFormat("%.2fx", c.wall_ms / matrix_ms), Count(c.stats.windows_created),
                  MiBOfBytes(static_cast<double>(c.stats.peak_bytes)), DeltaMiB(o, *mesh), vs,
                  OtherLoad(o)});
      return out;
    };
    s.table.AddRow(row("distance matrix 16 x 16", matrix, kSide, repeat, "0"));
    s.table.AddRow(row("16 full fields", fields, kSide, repeat, ""));
    s.table.AddRow(
        row("256 A* queries", queries, static_cast<int>(cells), query_repeat, Sci(query_rel)));
    int vertex_points = 0;
    for (const SurfacePoint& p : all) vertex_points += p.kind == SurfacePoint::Kind::kVertex;
    if (queries.ok() && queries.distance.size() == 2 * cells) {
      const std::vector<double> per_query(queries.distance.begin() + cells, queries.distance.end());
      s.notes.push_back(absl::StrFormat(
          "%s: the 256 A* queries took %s ms each at the median (%s-%s ms)", mesh->name,
          Ms(Median(per_query)), Ms(MinOf(per_query)), Ms(MaxOf(per_query))));
    }
    if (matrix.ok() && fields.ok() && queries.ok()) {
      const bool beats = matrix.report.wall_ms < fields.report.wall_ms &&
                         matrix.report.wall_ms < queries.report.wall_ms;
      s.notes.push_back(absl::StrFormat(
          "%s: 16 full fields take %.2fx the matrix's time and 256 A* queries %.2fx (%s); the "
          "matrix's solves create %.0f%% of the windows of the 16 full fields; its values equal "
          "the A* distances to %s relative",
          mesh->name, fields.report.wall_ms / matrix.report.wall_ms,
          queries.report.wall_ms / matrix.report.wall_ms,
          beats ? "the matrix beats both" : "the matrix does NOT beat both",
          100.0 * static_cast<double>(matrix.report.stats.windows_created) /
              static_cast<double>(std::max<uint64_t>(1, fields.report.stats.windows_created)),
          Sci(query_rel)));
    }
    std::vector<std::string> sources, targets;
    for (int k = 0; k < kSide; ++k) {
      sources.push_back(ShortPoint(all[k]));
      targets.push_back(ShortPoint(all[kSide + k]));
    }
    s.notes.push_back(absl::StrFormat(
        "%s: %d of the 32 points are vertices; sources: %s; "
        "targets: %s",
        mesh->name, vertex_points, absl::StrJoin(sources, ", "), absl::StrJoin(targets, ", ")));
  }
  return {s};
}

}  // namespace geodex::bench
