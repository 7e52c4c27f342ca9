// --ablation: ICH with its two pruning rules, the filter (Lemma 2) and one angle one split
// (Lemma 1), switched on and off, on each mesh and source.

#include <cstdint>
#include <cstdio>
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

std::vector<Section> RunAblation(const Config& config, const std::vector<MeshInfo>& meshes) {
  Section s{"Ablation: Lemma 1 (one angle one split) and Lemma 2 (filter)",
            "ICH with the two pruning rules switched on and off (all four combinations are exact). "
            "Budget: max_windows = 50 x the windows of the default run; a run that hits it stops "
            "with ResourceExhausted (\"budget exceeded\"). diff = max abs difference from the "
            "default run's field.",
            Table({"mesh", "source", "filter (L2)", "one split (L1)", "status", "solve ms",
                   "wall ms", "windows created", "filtered", "one-split removed", "processed",
                   "max level", "peak live", "peak MiB", "delta RSS MiB", "max abs diff"},
                  "lrlll"),
            {}};
  bool first = true;
  for (const MeshInfo& mesh : meshes) {
    const int repeat = RepeatFor(config, mesh);
    for (uint32_t source : mesh.sources) {
      if (!first) s.table.AddBreak();
      first = false;
      std::fprintf(stderr, "ablation: %s, source %u, R = %d\n", mesh.name.c_str(), source, repeat);
      const std::vector<uint32_t> src = {source};
      const Outcome reference = RunGeodex(mesh, src, GeodesicOptions{}, repeat, true, config);
      Progress("filter on, one split on", reference);
      if (!reference.ok()) {  // no budget to give the variants: they could eat all memory
        s.notes.push_back(absl::StrCat(mesh.name, " source ", source, ": the default run failed (",
                                       reference.StatusText(), " ", reference.message,
                                       "); variants skipped"));
        continue;
      }
      const uint64_t budget = 50 * reference.report.stats.windows_created;
      for (const bool filter : {true, false}) {
        for (const bool one_split : {true, false}) {
          GeodesicOptions options;
          options.use_filter = filter;
          options.use_one_angle_one_split = one_split;
          options.max_windows = budget;
          const bool is_reference = filter && one_split;
          Outcome run =
              is_reference ? reference : RunGeodex(mesh, src, options, repeat, true, config);
          if (!is_reference) {
            Progress(absl::StrFormat("filter %s, one split %s", filter ? "on" : "off",
                                     one_split ? "on" : "off"),
                     run);
          }
          std::vector<std::string> cells = {mesh.name, Count(source), filter ? "on" : "off",
                                            one_split ? "on" : "off", run.StatusText()};
          const SolveStats& st = run.report.stats;
          if (run.ok()) {
            cells.insert(
                cells.end(),
                {Ms(run.report.solve_ms), Ms(run.report.wall_ms), Count(st.windows_created),
                 Count(FilteredWindows(st)),
                 Count(st.children_skipped_one_split + st.windows_deleted_one_split),
                 Count(st.windows_processed), Count(st.max_level), Count(st.peak_live_windows),
                 MiBOfBytes(static_cast<double>(st.peak_bytes)), DeltaMiB(run, mesh)});
            cells.push_back(Sci(Compare(run.distance, reference.distance).max_abs));
          } else {
            cells.insert(cells.end(),
                         {"", Ms(run.elapsed_s * 1000),
                          run.kind == Outcome::kBudget ? absl::StrCat(">", budget) : "", "", "", "",
                          "", "", "", DeltaMiB(run, mesh), ""});
            if (run.kind != Outcome::kBudget && !run.message.empty()) {
              s.notes.push_back(absl::StrCat(mesh.name, " source ", source, ": ", run.message));
            }
          }
          s.table.AddRow(cells);
        }
      }
    }
  }
  s.notes.push_back(
      "one-split removed = second children not made (Lemma 1) + windows of a "
      "beaten owner's subtree deleted; for a failed run wall ms is the child's "
      "lifetime including the mesh load");
  return {s};
}

}  // namespace geodex::bench
