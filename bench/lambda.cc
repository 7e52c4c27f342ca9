// --lambda: the precision knob of section 7 of Xin & Wang 2010 (epsilon = lambda x an edge length
// added to the filter), from exact ICH (lambda = 0) towards Dijkstra's field, with its errors.

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "child_tasks.h"
#include "config.h"
#include "geodex/geodesic_solver.h"
#include "harness/table.h"
#include "measurements.h"
#include "meshes.h"
#include "sections.h"

namespace geodex::bench {

std::vector<Section> RunLambda(const Config& config, const std::vector<MeshInfo>& meshes) {
  Section s{"Precision knob lambda (section 7)",
            "epsilon = lambda x (longest edge | mean edge) is added to the filter's left side; "
            "lambda = 0 is exact ICH. Errors against the exact (lambda = 0) field over vertices "
            "with a positive distance: max and mean of |d - d_exact| / d_exact; changed = "
            "vertices whose distance differs at all. vs Dijkstra = max |d - d_Dijkstra| (0 means "
            "Dijkstra's field exactly, Theorem 8).",
            Table({"mesh", "source", "scale", "lambda", "epsilon", "solve ms", "x Dijkstra",
                   "windows created", "over-filtered", "max level", "max rel err", "mean rel err",
                   "changed", "vs Dijkstra"},
                  "lrl"),
            {}};
  const std::vector<double> lambdas = {0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0};
  bool first = true;
  for (const MeshInfo& mesh : meshes) {
    const int repeat = RepeatFor(config, mesh);
    for (uint32_t source : mesh.sources) {
      std::fprintf(stderr, "lambda: %s, source %u, R = %d\n", mesh.name.c_str(), source, repeat);
      const std::vector<uint32_t> src = {source};
      GeodesicOptions dijkstra_options;
      dijkstra_options.method = Method::kDijkstra;
      const Outcome dijkstra = RunGeodex(mesh, src, dijkstra_options, repeat, true, config);
      Progress("dijkstra", dijkstra);
      std::optional<Outcome> exact;
      for (const LambdaScale scale : {LambdaScale::kMaxEdge, LambdaScale::kMeanEdge}) {
        if (!first) s.table.AddBreak();
        first = false;
        const bool max_edge = scale == LambdaScale::kMaxEdge;
        const double length = max_edge ? mesh.report.max_edge : mesh.report.mean_edge;
        for (const double lambda : lambdas) {
          GeodesicOptions options;
          options.lambda = lambda;
          options.lambda_scale = scale;
          const Outcome run = RunGeodex(mesh, src, options, repeat, true, config);
          Progress(absl::StrFormat("%s lambda %g", max_edge ? "max edge" : "mean edge", lambda),
                   run);
          if (lambda == 0 && !exact && run.ok()) exact = run;
          std::vector<std::string> cells = {
              mesh.name, Count(source), max_edge ? "max edge" : "mean edge",
              absl::StrFormat("%g", lambda), absl::StrFormat("%.3g", lambda * length)};
          if (!run.ok()) {
            cells.push_back(run.StatusText());
            if (!run.message.empty()) {
              s.notes.push_back(absl::StrCat(mesh.name, " lambda ", lambda, ": ", run.message));
            }
            s.table.AddRow(cells);
            continue;
          }
          const SolveStats& st = run.report.stats;
          cells.insert(cells.end(),
                       {Ms(run.report.solve_ms),
                        dijkstra.ok() ? Ratio(run.report.solve_ms / dijkstra.report.solve_ms) : "",
                        Count(st.windows_created), Count(st.windows_filtered_overfilter),
                        Count(st.max_level)});
          if (exact) {
            const FieldDiff d = Compare(run.distance, exact->distance);
            cells.insert(cells.end(),
                         {Sci(d.max_pointwise_rel), Sci(d.mean_pointwise_rel), Count(d.changed)});
            if (d.finiteness_mismatch > 0) {
              s.notes.push_back(absl::StrCat(mesh.name, " lambda ", lambda, ": ",
                                             d.finiteness_mismatch,
                                             " vertices reached in only one of the two fields"));
            }
          } else {
            cells.insert(cells.end(), {"", "", ""});
          }
          cells.push_back(dijkstra.ok() ? Sci(Compare(run.distance, dijkstra.distance).max_abs)
                                        : "");
          s.table.AddRow(cells);
        }
      }
      if (dijkstra.ok() && exact) {
        const FieldDiff d = Compare(dijkstra.distance, exact->distance);
        s.notes.push_back(
            absl::StrFormat("%s source %u: Dijkstra itself: %s ms, max rel err %s, mean rel err %s",
                            mesh.name, source, Ms(dijkstra.report.solve_ms),
                            Sci(d.max_pointwise_rel), Sci(d.mean_pointwise_rel)));
      }
    }
  }
  return {s};
}

}  // namespace geodex::bench
