// geodex_bench: times our exact ICH, Dijkstra on the edge graph and (when built with CGAL)
// CGAL's Surface_mesh_shortest_path from the same sources in one run, and reports window counts,
// memory and the ICH-vs-CGAL difference. Extra modes: --ablation (Lemma 1 / Lemma 2 on and
// off), --lambda (the precision knob of section 7 of Xin & Wang 2010), and the targeted queries of
// its sections 4 and 5: --astar (exact A* paths vs solving the whole field, its Table 2),
// --matrix (a distance matrix vs full fields vs pairwise A*) and --estimate (the unfolding
// estimate at surface points vs the exact value, its Table 1 / Fig. 6).
//
// Every measurement runs in its own fork()ed child that loads the mesh itself; the parent never
// loads a mesh. Each child resets its RSS high-water mark right after loading (Linux
// /proc/self/clear_refs "5"), so its ru_maxrss (from wait4) is the peak while the method ran; a
// baseline child that only loads gives the resident size of the loaded mesh, and the difference is
// what the method itself needed at its peak. Results come back through a pipe; a child that runs
// past --timeout-s is killed.
//
// This file is Main: it reads the flags (config.h), finds and loads the meshes (meshes.h), runs
// the sections the flags ask for (sections.h: one file per section) and prints their tables. The
// harness under them (forked children, peak memory, peers, tables, the command line) is the
// library geodex_bench_harness in harness/; figures of other projects are data, in
// data/peer_figures.tsv.
//
// See docs/performance.md for how to run it and for the numbers.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "bench_build_info.h"  // generated: GEODEX_BENCH_BUILT_FROM
#include "config.h"
#include "dem_grids.h"
#include "harness/child_runner.h"
#include "harness/cli.h"
#include "harness/machine.h"
#include "harness/table.h"
#include "meshes.h"
#include "sections.h"

#ifndef GEODEX_SOURCE_DIR
#define GEODEX_SOURCE_DIR "."
#endif
#ifdef GEODEX_BENCH_BUILT_FROM
#define GEODEX_BUILD_FROM_OR_UNKNOWN GEODEX_BENCH_BUILT_FROM
#else
#define GEODEX_BUILD_FROM_OR_UNKNOWN "unknown"
#endif
#ifndef GEODEX_BUILD_TYPE
#define GEODEX_BUILD_TYPE "unknown"
#endif

namespace geodex::bench {
namespace {

int Main(int argc, char** argv) {
  absl::StatusOr<Config> parsed = ParseArgs(argc, argv);
  if (!parsed.ok()) {
    std::fprintf(stderr, "geodex_bench: %s\n%s", std::string(parsed.status().message()).c_str(),
                 kUsage);
    return 2;
  }
  Config config = *std::move(parsed);

  // The meshes: --meshes DIR (or the default directory when no --mesh is given) plus --mesh files.
  std::vector<std::string> paths;
  if (!config.meshes_dir_given && config.mesh_files.empty()) {
    config.meshes_dir = std::string(GEODEX_SOURCE_DIR) + "/../shared/meshes";
  }
  if (!config.meshes_dir.empty()) {
    std::error_code error;
    if (!std::filesystem::is_directory(config.meshes_dir, error)) {
      std::printf("geodex_bench: no mesh directory %s: nothing to do from it\n",
                  config.meshes_dir.c_str());
      if (config.meshes_dir_given) return 1;
    } else {
      paths = MeshFilesIn(config.meshes_dir);
    }
  }
  if (PointQueryMode(config) && config.mesh_files.empty()) {
    // Only the default meshes of the modes asked for.
    std::vector<std::string> keep;
    if (config.astar) keep.insert(keep.end(), AstarMeshes().begin(), AstarMeshes().end());
    if (config.matrix) keep.insert(keep.end(), MatrixMeshes().begin(), MatrixMeshes().end());
    if (config.estimate) keep.insert(keep.end(), EstimateMeshes().begin(), EstimateMeshes().end());
    std::erase_if(paths, [&](const std::string& path) {
      return std::find(keep.begin(), keep.end(), MeshName(path)) == keep.end();
    });
  }
  for (const std::string& f : config.mesh_files) paths.push_back(f);
  std::string dem_dir;
  if (config.terrain) {
    for (const std::string& f : WriteDemGrids(config, &dem_dir)) paths.push_back(f);
  }
  if (paths.empty()) {
    std::printf("geodex_bench: no meshes given (see --help); skipping\n");
    return 0;
  }

  const std::string header = absl::StrFormat(
      "geodex_bench: %s; %s; %s build; CPU %s, %d usable core(s); load average at start %s; "
      "each measurement in its own process, one at a time",
      UtcNow(), GitDescription(GEODEX_BUILD_FROM_OR_UNKNOWN, GEODEX_SOURCE_DIR), GEODEX_BUILD_TYPE,
      CpuModel(), UsableCpus(), LoadAverage());
  std::printf("%s\n", header.c_str());
#ifndef NDEBUG
  std::printf("WARNING: assertions are on (not a Release build): times are not representative\n");
#endif
#ifndef GEODEX_BENCH_WITH_CGAL
  std::printf("note: built without CGAL: no CGAL column\n");
#endif

  const std::vector<MeshInfo> meshes = LoadMeshes(config, paths);
  std::vector<Section> sections = {MeshSection(meshes)};
  auto add = [&sections](std::vector<Section> more) {
    for (Section& s : more) sections.push_back(std::move(s));
  };
  if (!config.ablation && !config.lambda && !PointQueryMode(config)) {
    add(RunEngineTable(config, meshes));
  }
  if (config.ablation) add(RunAblation(config, meshes));
  if (config.lambda) add(RunLambda(config, meshes));
  if (config.astar) add(RunAstar(config, meshes));
  if (config.matrix) add(RunMatrix(config, meshes));
  if (config.estimate) add(RunEstimate(config, meshes));

  const MeasurementLoad& load = MeasurementLoadSoFar();
  const std::string footer = absl::StrFormat(
      "load average at the end: %s; %d of %d measurements (of 50 ms or more) ran while other "
      "processes used a quarter of a core or more (at most %.2f cores)",
      LoadAverage(), load.busy, load.all, load.max_other_load);
  std::string markdown = absl::StrCat("<!-- ", header, " -->\n");
  markdown += PrintSections(sections);
  std::printf("\n%s\n", footer.c_str());
  absl::StrAppend(&markdown, "\n<!-- ", footer, " -->\n");
  if (!config.markdown.empty()) {
    std::ofstream out(config.markdown);
    out << markdown;
    if (!out) {
      std::fprintf(stderr, "geodex_bench: cannot write %s\n", config.markdown.c_str());
      return 1;
    }
    std::printf("\nwrote %s\n", config.markdown.c_str());
  }
  if (!dem_dir.empty()) {
    std::error_code ignored;
    std::filesystem::remove_all(dem_dir, ignored);
  }
  return 0;
}

}  // namespace
}  // namespace geodex::bench

int main(int argc, char** argv) { return geodex::bench::Main(argc, argv); }
