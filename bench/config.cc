#include "config.h"

#include <cstdio>
#include <cstdlib>
#include <string>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "harness/cli.h"

namespace geodex::bench {

bool PointQueryMode(const Config& config) {
  return config.astar || config.matrix || config.estimate;
}

const char kUsage[] =
    "usage: geodex_bench [--meshes DIR] [--mesh FILE ...] [--sources N] [--repeat R]\n"
    "                    [--cgal-max-faces F] [--methods exact,ich,dijkstra,cgal]\n"
    "                    [--terrain] [--large] [--peer NAME=COMMAND] [--markdown OUT.md]\n"
    "                    [--timeout-s T] [--wait-idle S] [--ablation] [--lambda]\n"
    "                    [--astar] [--matrix] [--estimate] [--seed N] [--per-group N]\n"
    "                    [--points N] [--batch N]\n"
    "\n"
    "  --meshes DIR        every mesh file in DIR (.off .obj .ply .stl, optionally .gz); default\n"
    "                      ../shared/meshes next to the source tree, unless --mesh is given\n"
    "  --mesh FILE         a mesh file (repeatable; added to --meshes DIR when both are given)\n"
    "  --sources N         single-source runs per mesh (default 2): vertex 0, then the smallest\n"
    "                      vertex id >= V/2 in the largest component, then >= V/4, 3V/4, V/8, ...\n"
    "  --repeat R          repeats per measurement, the median is reported (default: 3 below\n"
    "                      100k faces, 1 above)\n"
    "  --cgal-max-faces F  run CGAL only on meshes with at most F faces (default 100000)\n"
    "  --methods LIST      any of exact (geodex's default engine), ich (the paper's ICH with its\n"
    "                      window tree), dijkstra, cgal (default exact,dijkstra,cgal)\n"
    "  --terrain           add DEM-like grids made at run time: a bumpy terrain and the same\n"
    "                      with half of it exactly flat (a lake at its median height), ~89k faces\n"
    "  --large             with --terrain: also their 1M-face versions (707 x 707 vertices)\n"
    "  --terrain-dir DIR   with --terrain: write the grids (OFF) into DIR and keep them\n"
    "  --peer NAME=CMD     also time another exact code: `CMD MESH SOURCE OUT` must write the\n"
    "                      distances of every file vertex as raw doubles to OUT and print a line\n"
    "                      starting ms=<propagation ms>; its peak RSS comes from wait4 (the\n"
    "                      largest of its processes); repeatable\n"
    "  --markdown OUT.md   also write the tables as Markdown\n"
    "  --timeout-s T       kill a measurement after T seconds (default 300)\n"
    "  --wait-idle S       before each measurement wait up to S seconds until the other\n"
    "                      processes use less than a quarter of a core (default 0: no wait)\n"
    "  --ablation          instead of the main table: ICH with the filter (Lemma 2) and one angle\n"
    "                      one split (Lemma 1) on/off, on each given mesh\n"
    "  --lambda            instead of the main table: lambda in {0 .. 1} x {max edge, mean edge}\n"
    "  --astar             instead of the main table: exact paths from vertex 0 to random target\n"
    "                      points, A* (section 5) vs solving the whole field, grouped by the\n"
    "                      target's distance (default meshes: gargoyle, armadillo)\n"
    "  --matrix            instead of the main table: a 16 x 16 distance matrix between random\n"
    "                      points vs 16 full fields vs 256 A* queries (default mesh: armadillo)\n"
    "  --estimate          instead of the main table: the unfolding estimate at random face "
    "points\n"
    "                      (section 4) vs the exact distance, the straight line and Dijkstra\n"
    "                      (default meshes: gargoyle armadillo fertility kitten bunny-npm\n"
    "                      camelhead face)\n"
    "  --seed N            seed of the random points of the three modes above (default 2010)\n"
    "  --per-group N       --astar: target points per distance group (default 12)\n"
    "  --points N          --estimate: face points per mesh (default 1000)\n"
    "  --batch N           --estimate: points per exact solve (default 100)\n"
    "\n"
    "Without --mesh, --astar, --matrix and --estimate take their default meshes from the mesh\n"
    "directory. The --astar pairs and the matrix and fields of --matrix run R times\n"
    "(--repeat, default 3 below 100k faces and 1 above); the 256 queries of --matrix default\n"
    "to 1, and --estimate runs once.\n";

absl::StatusOr<Config> ParseArgs(int argc, char** argv) {
  Config config;
  ArgReader args(argc, argv);
  while (args.Next()) {
    const std::string& arg = args.flag();
    if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (arg == "--ablation") {
      config.ablation = true;
    } else if (arg == "--lambda") {
      config.lambda = true;
    } else if (arg == "--astar") {
      config.astar = true;
    } else if (arg == "--matrix") {
      config.matrix = true;
    } else if (arg == "--estimate") {
      config.estimate = true;
    } else if (arg == "--terrain") {
      config.terrain = true;
    } else if (arg == "--large") {
      config.large = true;
    } else if (arg == "--meshes" || arg == "--mesh" || arg == "--sources" || arg == "--repeat" ||
               arg == "--cgal-max-faces" || arg == "--methods" || arg == "--markdown" ||
               arg == "--timeout-s" || arg == "--wait-idle" || arg == "--seed" ||
               arg == "--per-group" || arg == "--points" || arg == "--batch" || arg == "--peer" ||
               arg == "--terrain-dir") {
      absl::StatusOr<std::string> v = args.Value();
      if (!v.ok()) return v.status();
      if (arg == "--meshes") {
        config.meshes_dir = *v;
        config.meshes_dir_given = true;
      } else if (arg == "--mesh") {
        config.mesh_files.push_back(*v);
      } else if (arg == "--sources") {
        if (!absl::SimpleAtoi(*v, &config.sources) || config.sources < 1 ||
            config.sources > kMaxSources) {
          return args.Bad(*v);
        }
      } else if (arg == "--repeat") {
        if (!absl::SimpleAtoi(*v, &config.repeat) || config.repeat < 1) return args.Bad(*v);
      } else if (arg == "--cgal-max-faces") {
        if (!absl::SimpleAtoi(*v, &config.cgal_max_faces)) return args.Bad(*v);
      } else if (arg == "--terrain-dir") {
        config.terrain_dir = *v;
      } else if (arg == "--peer") {
        const size_t eq = v->find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == v->size()) return args.Bad(*v);
        config.peers.emplace_back(v->substr(0, eq), v->substr(eq + 1));
      } else if (arg == "--methods") {
        config.run_ich = config.run_dijkstra = config.run_cgal = config.run_paper = false;
        for (absl::string_view m : absl::StrSplit(*v, ',', absl::SkipEmpty())) {
          if (m == "exact") {
            config.run_ich = true;
          } else if (m == "ich") {
            config.run_paper = true;
          } else if (m == "dijkstra") {
            config.run_dijkstra = true;
          } else if (m == "cgal") {
            config.run_cgal = true;
          } else {
            return args.Bad(*v);
          }
        }
      } else if (arg == "--markdown") {
        config.markdown = *v;
      } else if (arg == "--timeout-s") {
        if (!absl::SimpleAtod(*v, &config.timeout_s) || !(config.timeout_s > 0))
          return args.Bad(*v);
      } else if (arg == "--wait-idle") {
        if (!absl::SimpleAtod(*v, &config.wait_idle_s) || !(config.wait_idle_s >= 0)) {
          return args.Bad(*v);
        }
      } else if (arg == "--seed") {
        if (!absl::SimpleAtoi(*v, &config.seed)) return args.Bad(*v);
      } else if (arg == "--per-group") {
        if (!absl::SimpleAtoi(*v, &config.per_group) || config.per_group < 1 ||
            config.per_group > 1000) {
          return args.Bad(*v);
        }
      } else if (arg == "--points") {
        if (!absl::SimpleAtoi(*v, &config.points) || config.points < 1 ||
            config.points > 1'000'000) {
          return args.Bad(*v);
        }
      } else if (arg == "--batch") {
        if (!absl::SimpleAtoi(*v, &config.batch) || config.batch < 1) return args.Bad(*v);
      }
    } else {
      return args.Unknown();
    }
  }
#ifndef GEODEX_BENCH_WITH_CGAL
  config.run_cgal = false;
#endif
  return config;
}

}  // namespace geodex::bench
