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
// See docs/performance.md for how to run it and for the numbers.

#include <fcntl.h>
#include <malloc.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#ifdef GEODEX_BENCH_WITH_CGAL
#include "util/cgal_reference.h"
#endif
#include "bench_build_info.h"  // generated: GEODEX_BENCH_BUILT_FROM

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

namespace geodex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxSources = 16;
constexpr double kMiB = 1024.0 * 1024.0;

// ------------------------------------------------------------------------------------------------
// Configuration

struct Config {
  std::string meshes_dir;
  bool meshes_dir_given = false;
  std::vector<std::string> mesh_files;
  int sources = 2;
  int repeat = 0;  // 0: 3 below 100k faces, 1 from 100k faces on
  uint64_t cgal_max_faces = 100'000;
  // run_ich: geodex's default exact engine (Method::kExact, "exact" in --methods); run_paper: the
  // paper's ICH with its window tree (Method::kIch, "ich").
  bool run_ich = true, run_dijkstra = true, run_cgal = true, run_paper = false;
  // --terrain: DEM-like grids made here (bumpy, and half exactly flat); --large: also 1M faces.
  bool terrain = false, large = false;
  std::string terrain_dir;  // --terrain-dir: write the grids there and keep them
  // --peer NAME=COMMAND: another exact code, run as `COMMAND MESH SOURCE OUT` (see kUsage).
  std::vector<std::pair<std::string, std::string>> peers;
  std::string markdown;
  double timeout_s = 300;
  double wait_idle_s = 0;
  bool ablation = false;
  bool lambda = false;
  // The targeted-query modes (sections 4 and 5 of the paper).
  bool astar = false, matrix = false, estimate = false;
  uint64_t seed = 2010;  // the random points of --astar, --matrix and --estimate
  int per_group = 12;    // --astar: target points per distance group
  int points = 1000;     // --estimate: face points per mesh
  int batch = 100;       // --estimate: points per ComputeExactDistancesAt call
};

// Without --mesh, each targeted-query mode takes these meshes from the mesh directory.
const std::vector<std::string>& AstarMeshes() {
  static const std::vector<std::string> names = {"gargoyle", "armadillo"};
  return names;
}
const std::vector<std::string>& MatrixMeshes() {
  static const std::vector<std::string> names = {"armadillo"};
  return names;
}
const std::vector<std::string>& EstimateMeshes() {
  static const std::vector<std::string> names = {"gargoyle",  "armadillo", "fertility", "kitten",
                                                 "bunny-npm", "camelhead", "face"};
  return names;
}

bool PointQueryMode(const Config& config) {
  return config.astar || config.matrix || config.estimate;
}

constexpr char kUsage[] =
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
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    std::string value;
    bool has_value = false;
    if (const size_t eq = arg.find('='); absl::StartsWith(arg, "--") && eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      has_value = true;
    }
    auto next = [&]() -> absl::StatusOr<std::string> {
      if (has_value) return value;
      if (i + 1 >= argc) return absl::InvalidArgumentError(absl::StrCat(arg, " needs a value"));
      return std::string(argv[++i]);
    };
    auto bad = [&](const std::string& v) {
      return absl::InvalidArgumentError(absl::StrCat("bad value for ", arg, ": '", v, "'"));
    };
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
      absl::StatusOr<std::string> v = next();
      if (!v.ok()) return v.status();
      if (arg == "--meshes") {
        config.meshes_dir = *v;
        config.meshes_dir_given = true;
      } else if (arg == "--mesh") {
        config.mesh_files.push_back(*v);
      } else if (arg == "--sources") {
        if (!absl::SimpleAtoi(*v, &config.sources) || config.sources < 1 ||
            config.sources > kMaxSources) {
          return bad(*v);
        }
      } else if (arg == "--repeat") {
        if (!absl::SimpleAtoi(*v, &config.repeat) || config.repeat < 1) return bad(*v);
      } else if (arg == "--cgal-max-faces") {
        if (!absl::SimpleAtoi(*v, &config.cgal_max_faces)) return bad(*v);
      } else if (arg == "--terrain-dir") {
        config.terrain_dir = *v;
      } else if (arg == "--peer") {
        const size_t eq = v->find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == v->size()) return bad(*v);
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
            return bad(*v);
          }
        }
      } else if (arg == "--markdown") {
        config.markdown = *v;
      } else if (arg == "--timeout-s") {
        if (!absl::SimpleAtod(*v, &config.timeout_s) || !(config.timeout_s > 0)) return bad(*v);
      } else if (arg == "--wait-idle") {
        if (!absl::SimpleAtod(*v, &config.wait_idle_s) || !(config.wait_idle_s >= 0)) {
          return bad(*v);
        }
      } else if (arg == "--seed") {
        if (!absl::SimpleAtoi(*v, &config.seed)) return bad(*v);
      } else if (arg == "--per-group") {
        if (!absl::SimpleAtoi(*v, &config.per_group) || config.per_group < 1 ||
            config.per_group > 1000) {
          return bad(*v);
        }
      } else if (arg == "--points") {
        if (!absl::SimpleAtoi(*v, &config.points) || config.points < 1 ||
            config.points > 1'000'000) {
          return bad(*v);
        }
      } else if (arg == "--batch") {
        if (!absl::SimpleAtoi(*v, &config.batch) || config.batch < 1) return bad(*v);
      }
    } else {
      return absl::InvalidArgumentError(absl::StrCat("unknown argument '", arg, "'"));
    }
  }
#ifndef GEODEX_BENCH_WITH_CGAL
  config.run_cgal = false;
#endif
  return config;
}

bool IsMeshFileName(const std::string& name) {
  std::string n = name;
  if (absl::EndsWith(n, ".gz")) n.resize(n.size() - 3);
  return absl::EndsWith(n, ".off") || absl::EndsWith(n, ".obj") || absl::EndsWith(n, ".ply") ||
         absl::EndsWith(n, ".stl");
}

std::string MeshName(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  if (absl::EndsWith(name, ".gz")) name.resize(name.size() - 3);
  if (const size_t dot = name.rfind('.'); dot != std::string::npos) name.resize(dot);
  return name;
}

// ------------------------------------------------------------------------------------------------
// Machine and build description

std::string RunCommand(const std::string& command) {
  std::string out;
  if (FILE* p = popen(command.c_str(), "r")) {
    char buf[256];
    while (fgets(buf, sizeof(buf), p) != nullptr) out += buf;
    pclose(p);
  }
  return out;
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (absl::StartsWith(line, "model name")) {
      if (const size_t colon = line.find(':'); colon != std::string::npos) {
        return std::string(absl::StripAsciiWhitespace(line.substr(colon + 1)));
      }
    }
  }
  return "unknown";
}

int UsableCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return CPU_COUNT(&set);
  return static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
}

// The commit the binary was built from; the checkout's HEAD too if it has moved since.
std::string GitDescription() {
  std::string description = absl::StrCat("built from ", GEODEX_BUILD_FROM_OR_UNKNOWN);
  const std::string head(absl::StripAsciiWhitespace(
      RunCommand("git -C '" GEODEX_SOURCE_DIR "' rev-parse --short HEAD 2>/dev/null")));
  if (!head.empty() && !absl::StartsWith(GEODEX_BUILD_FROM_OR_UNKNOWN, head)) {
    absl::StrAppend(&description, " (the checkout is now at ", head, ": rebuild?)");
  }
  return description;
}

std::string UtcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm;
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

// ------------------------------------------------------------------------------------------------
// DEM-like grids (--terrain)

// A height field on n x n grid points over the unit square, like a DEM: vertex (row, col) has id
// row * n + col, every cell split into two triangles along the same diagonal. The relief is 60
// Gaussian bumps and pits (seeded, so every run makes the same grid). With `flat_share` > 0 every
// height below the flat_share quantile becomes exactly that quantile: a lake or sea stored at one
// level, the flat areas real DEMs have.
MeshData MakeDemGrid(int n, double flat_share, uint64_t seed) {
  struct Bump {
    double x, y, amplitude, width;
  };
  std::vector<Bump> bumps;
  uint64_t state = seed;
  auto uniform = [&]() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (int k = 0; k < 60; ++k) {
    Bump b;
    b.x = uniform();
    b.y = uniform();
    b.amplitude = (uniform() < 0.5 ? -1 : 1) * (0.02 + 0.06 * uniform());
    b.width = 0.03 + 0.07 * uniform();
    bumps.push_back(b);
  }
  MeshData m;
  m.positions.reserve(3 * size_t(n) * n);
  std::vector<double> heights;
  for (int row = 0; row < n; ++row) {
    for (int col = 0; col < n; ++col) {
      const double x = col / double(n - 1), y = row / double(n - 1);
      double z = 0;
      for (const Bump& b : bumps) {
        const double r2 = (x - b.x) * (x - b.x) + (y - b.y) * (y - b.y);
        z += b.amplitude * std::exp(-r2 / (2 * b.width * b.width));
      }
      m.positions.insert(m.positions.end(), {x, y, z});
      heights.push_back(z);
    }
  }
  if (flat_share > 0) {
    std::vector<double> sorted = heights;
    const size_t k = static_cast<size_t>(flat_share * (sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    const double level = sorted[k];
    for (size_t v = 0; v < heights.size(); ++v) {
      m.positions[3 * v + 2] = std::max(heights[v], level);
    }
  }
  m.faces.reserve(6 * size_t(n - 1) * (n - 1));
  for (int row = 0; row + 1 < n; ++row) {
    for (int col = 0; col + 1 < n; ++col) {
      const uint32_t a = row * n + col, b = a + 1, c = a + n, d = c + 1;
      m.faces.insert(m.faces.end(), {a, b, d});
      m.faces.insert(m.faces.end(), {a, d, c});
    }
  }
  return m;
}

// Writes the --terrain grids as OFF files (full double precision, readable by peers) into a fresh
// directory under /tmp; returns their paths.
std::vector<std::string> WriteDemGrids(const Config& config, std::string* dir) {
  std::string out_dir = config.terrain_dir;
  if (out_dir.empty()) {
    char templ[] = "/tmp/geodex_bench_dem_XXXXXX";
    if (mkdtemp(templ) == nullptr) return {};
    out_dir = *dir = templ;  // removed at the end
  } else {
    std::error_code error;
    std::filesystem::create_directories(out_dir, error);
  }
  struct Grid {
    std::string name;
    int n;
    double flat;
  };
  std::vector<Grid> grids = {{"dem-bumpy-88k", 211, 0}, {"dem-half-flat-88k", 211, 0.5}};
  if (config.large) {
    grids.push_back({"dem-bumpy-997k", 707, 0});
    grids.push_back({"dem-half-flat-997k", 707, 0.5});
  }
  std::vector<std::string> paths;
  for (const Grid& g : grids) {
    const std::string path = out_dir + "/" + g.name + ".off";
    if (absl::Status st = WriteMeshOff(path, MakeDemGrid(g.n, g.flat, 2010)); !st.ok()) {
      std::fprintf(stderr, "geodex_bench: %s\n", std::string(st.message()).c_str());
      continue;
    }
    paths.push_back(path);
  }
  return paths;
}

// ------------------------------------------------------------------------------------------------
// Child processes

enum class Task : int32_t {
  kInfo,
  kGeodex,
  kCgal,
  kPlanTargets,   // --astar: the full field from sources[0], then target points by distance group
  kSamplePoints,  // `count` random points (seeded), sent back packed
  kPathPair,      // --astar: from[0] -> to[0], A* and full field, `repeat` times each
  kMatrix,        // --matrix: ComputeDistanceMatrix(from, to)
  kFields,        // --matrix: ComputeDistanceField per point of `from`
  kPathQueries,   // --matrix: ComputeShortestPath for every (from, to) pair
  kEstimate,  // --estimate: estimate vs exact vs straight line vs Dijkstra at random face points
};

// What a child does. `options` is used by kGeodex (its method picks ICH or Dijkstra).
struct Job {
  Task task = Task::kInfo;
  std::string path;
  int sources_wanted = 2;         // kInfo
  std::vector<uint32_t> sources;  // file vertex ids, one multi-source solve (one id: one source)
  GeodesicOptions options;
  int repeat = 1;
  bool want_distances = false;
  // The targeted-query tasks.
  std::vector<SurfacePoint> from, to;
  uint64_t seed = 0;
  int count = 0;               // kPlanTargets: points per group; kSamplePoints, kEstimate: points
  double vertex_share = 0.25;  // kPlanTargets, kSamplePoints: the share of vertex points
  int batch = 100;             // kEstimate
};

// What a child sends back, followed by `distance_count` doubles. Plain data: sent as bytes.
struct ChildReport {
  int32_t ok = 0;
  int32_t resource_exhausted = 0;
  char error[480] = {};
  // The mesh (every child fills these).
  uint64_t file_vertices = 0, vertices = 0, faces = 0, components = 0, isolated = 0;
  uint64_t largest_component_faces = 0;
  uint64_t saddles = 0, boundary_vertices = 0;
  double mean_edge = 0, max_edge = 0;
  double load_ms = 0;             // read + TriangleMesh::Build
  int64_t load_peak_kb = 0;       // ru_maxrss while loading (before the reset)
  int64_t rss_after_load_kb = 0;  // resident size once loaded
  int32_t hiwater_reset = 0;      // /proc/self/clear_refs worked
  int32_t source_count = 0;       // kInfo: the chosen sources
  uint32_t sources[kMaxSources] = {};
  // The measurement (medians over the repeats).
  int32_t runs = 0;
  double solve_ms = 0, wall_ms = 0, solve_ms_min = 0;
  double cpu_ms = 0;  // CPU time of the whole call (user + system): immune to time slicing
  double cgal_setup_ms = 0, cgal_query_ms = 0;
  SolveStats stats;
  // kPathPair: the A* run is in solve_ms / wall_ms / stats above, the full-field run here. The
  // peaks are the RSS high-water mark over the resident size when it was reset (before each of
  // the two runs); they need hiwater_reset.
  double full_solve_ms = 0, full_wall_ms = 0;
  SolveStats full_stats;
  double astar_distance = 0, full_distance = 0;
  int64_t astar_peak_kb = 0, full_peak_kb = 0;
  // kPlanTargets and kEstimate: the largest finite vertex distance from the source.
  double max_distance = 0;
  uint64_t candidates = 0;  // kPlanTargets: random points drawn to fill the groups
  double estimate_ms = 0;   // kEstimate: all estimates (the field's time is solve_ms)
  double exact_ms = 0;      // kEstimate: all exact solves (their windows are in stats)
  double dijkstra_ms = 0;   // kEstimate: the Dijkstra field
  int32_t exact_solves = 0;
  uint64_t distance_count = 0;  // doubles following the report (distances or other values)
};
static_assert(std::is_trivially_copyable_v<ChildReport>);

// The parent's view of one child.
struct Outcome {
  enum Kind { kOk, kError, kBudget, kTimeout, kCrashed } kind = kError;
  std::string message;
  ChildReport report;
  std::vector<double> distance;
  int64_t maxrss_kb = 0;  // the child's ru_maxrss from wait4
  double elapsed_s = 0;
  double other_load = 0;  // cores used by other processes while the child ran

  bool ok() const { return kind == kOk; }
  std::string StatusText() const {
    switch (kind) {
      case kOk:
        return "ok";
      case kBudget:
        return "budget exceeded";
      case kTimeout:
        return "timeout";
      case kCrashed:
        return message;
      case kError:
        break;
    }
    return "error";
  }
};

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double MsSince(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

double CpuMs() {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

// CPU seconds spent busy by the whole machine since boot (all cores), from /proc/stat.
double MachineBusySeconds() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  uint64_t user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
  in >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal;
  return static_cast<double>(user + nice + system + irq + softirq + steal) /
         static_cast<double>(sysconf(_SC_CLK_TCK));
}

// Load from other processes, in cores, over `seconds` (this process sleeps meanwhile).
double SampleOtherLoad(double seconds) {
  const double busy = MachineBusySeconds();
  usleep(static_cast<useconds_t>(seconds * 1e6));
  return (MachineBusySeconds() - busy) / seconds;
}

// Waits until other processes use less than a quarter of a core (sampled over 0.5 s), at most
// `max_s` seconds. Returns the last sample.
double WaitForIdle(double max_s) {
  if (max_s <= 0) return 0;
  const auto start = std::chrono::steady_clock::now();
  double load = SampleOtherLoad(0.5);
  bool said = false;
  while (load >= 0.25 && MsSince(start) < max_s * 1000) {
    if (!said) std::fprintf(stderr, "  (waiting for an idle machine: other load %.2f)\n", load);
    said = true;
    load = SampleOtherLoad(0.5);
  }
  return load;
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double one = 0, five = 0;
  in >> one >> five;
  return absl::StrFormat("%.2f (1 min), %.2f (5 min)", one, five);
}

int64_t CurrentRssKb() {
  std::ifstream in("/proc/self/statm");
  int64_t size = 0, resident = 0;
  in >> size >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

// Resets the kernel's RSS high-water mark of this process to its current RSS.
bool ResetRssHighWater() {
  const int fd = open("/proc/self/clear_refs", O_WRONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = write(fd, "5", 1) == 1;
  close(fd);
  return ok;
}

void WriteAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return;
    }
    data += n;
    size -= static_cast<size_t>(n);
  }
}

void SendReport(int fd, ChildReport& report, const std::vector<double>& distance) {
  report.distance_count = distance.size();
  std::string bytes(sizeof(report) + distance.size() * sizeof(double), '\0');
  std::memcpy(bytes.data(), &report, sizeof(report));
  if (!distance.empty()) {
    std::memcpy(bytes.data() + sizeof(report), distance.data(), distance.size() * sizeof(double));
  }
  WriteAll(fd, bytes.data(), bytes.size());
}

void SetError(ChildReport& report, const std::string& message) {
  report.ok = 0;
  std::snprintf(report.error, sizeof(report.error), "%s", message.c_str());
}

// Sources for a mesh: vertex 0, then for i >= 1 the smallest vertex id >= q_i * V in the largest
// component (by faces), q = 1/2, 1/4, 3/4, 1/8, 3/8, ... (for i = 1 this is MANIFEST.md's
// "suggested 2nd source").
std::vector<uint32_t> ChooseSources(const TriangleMesh& mesh, int wanted, uint64_t* largest_faces) {
  std::vector<uint32_t> faces_of(mesh.vertex_count(), 0);
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    ++faces_of[mesh.Component(mesh.FaceVertex(f, 0))];
  }
  const uint32_t largest =
      static_cast<uint32_t>(std::max_element(faces_of.begin(), faces_of.end()) - faces_of.begin());
  *largest_faces = faces_of[largest];
  const uint32_t nv = mesh.file_vertex_count();
  std::vector<uint32_t> sources = {0};
  for (int i = 1; static_cast<int>(sources.size()) < wanted && i < 4 * kMaxSources; ++i) {
    // Van der Corput (base 2) fraction of i.
    double q = 0, bit = 0.5;
    for (int k = i; k > 0; k >>= 1, bit *= 0.5) {
      if (k & 1) q += bit;
    }
    for (uint32_t v = static_cast<uint32_t>(std::floor(q * nv)); v < nv; ++v) {
      if (mesh.Component(v) == largest && !mesh.IsIsolated(v)) {
        if (std::find(sources.begin(), sources.end(), v) == sources.end()) sources.push_back(v);
        break;
      }
    }
  }
  return sources;
}

std::vector<SurfacePoint> AsSurfacePoints(const std::vector<uint32_t>& ids) {
  std::vector<SurfacePoint> points;
  for (uint32_t v : ids) points.push_back(SurfacePoint::AtVertex(v));
  return points;
}

// ------------------------------------------------------------------------------------------------
// Targeted queries (--astar, --matrix, --estimate): random points and the children

// SplitMix64: the same sequence on every platform and standard library (std:: distributions are
// not), so a seed names the same points everywhere.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  // [0, 1)
  uint64_t Below(uint64_t n) { return Next() % n; }  // the bias is below 1e-9 for n < 2^32

 private:
  uint64_t state_;
};

std::array<double, 3> FilePosition(const MeshData& data, uint32_t v) {
  return {data.positions[3 * v], data.positions[3 * v + 1], data.positions[3 * v + 2]};
}

double Distance3(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// Where a vertex or face point is, in file coordinates.
std::array<double, 3> PointPosition(const MeshData& data, const SurfacePoint& p) {
  if (p.kind == SurfacePoint::Kind::kVertex) return FilePosition(data, p.vertex);
  std::array<double, 3> q = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const std::array<double, 3> c = FilePosition(data, data.faces[3 * p.face + k]);
    for (int i = 0; i < 3; ++i) q[i] += p.bary[k] * c[i];
  }
  return q;
}

// Random points on the connected component of file vertex `anchor`: with probability
// `vertex_share` a vertex (uniform over the component's vertices), otherwise a face point
// uniform over the component's area (a face picked by area, then a uniform point inside it).
class PointSampler {
 public:
  PointSampler(const MeshData& data, const TriangleMesh& mesh, uint32_t anchor, double vertex_share,
               uint64_t seed)
      : rng_(seed), vertex_share_(vertex_share) {
    const uint32_t component = mesh.Component(anchor);
    for (uint32_t v = 0; v < mesh.file_vertex_count(); ++v) {
      if (mesh.Component(v) == component && !mesh.IsIsolated(v)) vertices_.push_back(v);
    }
    double total = 0;
    for (uint32_t f = 0; f < data.face_count() && f < mesh.face_count(); ++f) {
      if (mesh.FaceDegenerate(f) || mesh.Component(mesh.FaceVertex(f, 0)) != component) continue;
      const std::array<double, 3> a = FilePosition(data, data.faces[3 * f]);
      const std::array<double, 3> b = FilePosition(data, data.faces[3 * f + 1]);
      const std::array<double, 3> c = FilePosition(data, data.faces[3 * f + 2]);
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                           u[0] * w[1] - u[1] * w[0]};
      const double area = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (!(area > 0)) continue;
      total += area;
      faces_.push_back(f);
      cumulative_area_.push_back(total);
    }
  }

  bool ok() const { return !vertices_.empty() && !faces_.empty(); }

  SurfacePoint Next() {
    if (vertex_share_ > 0 && rng_.Uniform() < vertex_share_) {
      return SurfacePoint::AtVertex(vertices_[rng_.Below(vertices_.size())]);
    }
    const double x = rng_.Uniform() * cumulative_area_.back();
    const size_t i =
        std::min<size_t>(std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), x) -
                             cumulative_area_.begin(),
                         faces_.size() - 1);
    const double r1 = std::sqrt(rng_.Uniform()), r2 = rng_.Uniform();
    return SurfacePoint::InFace(faces_[i], 1 - r1, r1 * (1 - r2), r1 * r2);
  }

 private:
  Rng rng_;
  double vertex_share_;
  std::vector<uint32_t> vertices_, faces_;
  std::vector<double> cumulative_area_;
};

// Vertex and face points travel between processes as 5 doubles: kind, id, barycentrics.
constexpr size_t kPackedPoint = 5;

void PackPoint(const SurfacePoint& p, std::vector<double>* out) {
  if (p.kind == SurfacePoint::Kind::kVertex) {
    out->insert(out->end(), {0.0, static_cast<double>(p.vertex), 0.0, 0.0, 0.0});
  } else {
    out->insert(out->end(), {1.0, static_cast<double>(p.face), p.bary[0], p.bary[1], p.bary[2]});
  }
}

std::vector<SurfacePoint> UnpackPoints(const std::vector<double>& values) {
  std::vector<SurfacePoint> points;
  for (size_t i = 0; i + kPackedPoint <= values.size(); i += kPackedPoint) {
    const double* x = values.data() + i;
    const uint32_t id = static_cast<uint32_t>(x[1]);
    points.push_back(x[0] == 0 ? SurfacePoint::AtVertex(id)
                               : SurfacePoint::InFace(id, x[2], x[3], x[4]));
  }
  return points;
}

std::string ShortPoint(const SurfacePoint& p) {
  return p.kind == SurfacePoint::Kind::kVertex ? absl::StrCat("v ", p.vertex)
                                               : absl::StrCat("f ", p.face);
}

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

// The kernel's RSS high-water mark of this process (VmHWM), in KiB.
int64_t PeakRssKb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (absl::StartsWith(line, "VmHWM:")) {
      int64_t kb = 0;
      std::vector<std::string> parts = absl::StrSplit(line.substr(6), ' ', absl::SkipWhitespace());
      if (!parts.empty() && absl::SimpleAtoi(parts[0], &kb)) return kb;
    }
  }
  return 0;
}

double LargestFinite(const std::vector<double>& distance) {
  double largest = 0;
  for (double d : distance) {
    if (std::isfinite(d)) largest = std::max(largest, d);
  }
  return largest;
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

void AddUp(const SolveStats& s, SolveStats* total) {
  total->windows_created += s.windows_created;
  total->windows_processed += s.windows_processed;
  total->max_level = std::max(total->max_level, s.max_level);
  total->peak_live_windows = std::max(total->peak_live_windows, s.peak_live_windows);
  total->peak_bytes = std::max(total->peak_bytes, s.peak_bytes);
  total->solve_ms += s.solve_ms;
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

void ChildMain(const Job& job, int fd) {
  ChildReport report;
  std::vector<double> distance;
  const auto load_start = std::chrono::steady_clock::now();
  absl::StatusOr<MeshData> data = ReadMeshFile(job.path);
  if (!data.ok()) {
    SetError(report, data.status().ToString());
    SendReport(fd, report, distance);
    return;
  }
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  if (!mesh.ok()) {
    SetError(report, mesh.status().ToString());
    SendReport(fd, report, distance);
    return;
  }
  report.load_ms = MsSince(load_start);
  report.file_vertices = mesh->file_vertex_count();
  report.vertices = mesh->vertex_count();
  report.faces = mesh->face_count();
  report.components = mesh->report().components;
  report.isolated = mesh->report().isolated_vertices;
  report.saddles = mesh->report().saddle_vertices;
  report.boundary_vertices = mesh->report().boundary_vertices;
  report.mean_edge = mesh->MeanEdgeLength();
  report.max_edge = mesh->MaxEdgeLength();
  if (job.task == Task::kInfo) {  // before the baseline is taken
    const std::vector<uint32_t> sources =
        ChooseSources(*mesh, job.sources_wanted, &report.largest_component_faces);
    report.source_count = static_cast<int32_t>(sources.size());
    std::copy(sources.begin(), sources.end(), report.sources);
  }
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  report.load_peak_kb = usage.ru_maxrss;
  // Give the loader's freed buffers back to the system: otherwise they stay resident, a method
  // reuses them without growing the RSS, and its delta over the baseline looks too small.
  malloc_trim(0);
  report.rss_after_load_kb = CurrentRssKb();
  report.hiwater_reset = ResetRssHighWater();
  report.ok = 1;

  switch (job.task) {
    case Task::kInfo:
      break;
    case Task::kGeodex: {
      const std::vector<SurfacePoint> sources = AsSurfacePoints(job.sources);
      std::vector<double> solve, wall, cpu;
      std::optional<DistanceField> field;
      for (int r = 0; r < job.repeat; ++r) {
        field.reset();  // never two fields alive at once
        const auto start = std::chrono::steady_clock::now();
        const double cpu_start = CpuMs();
        absl::StatusOr<DistanceField> result = ComputeDistanceField(*mesh, sources, job.options);
        cpu.push_back(CpuMs() - cpu_start);
        wall.push_back(MsSince(start));
        if (!result.ok()) {
          SetError(report, result.status().ToString());
          report.resource_exhausted = absl::IsResourceExhausted(result.status());
          break;
        }
        field = *std::move(result);
        solve.push_back(field->stats.solve_ms);
        report.stats = field->stats;
      }
      report.runs = static_cast<int32_t>(solve.size());
      report.solve_ms = Median(solve);
      report.solve_ms_min = solve.empty() ? 0 : *std::min_element(solve.begin(), solve.end());
      report.wall_ms = Median(wall);
      report.cpu_ms = Median(cpu);
      if (report.ok && job.want_distances) distance = field->distance;
      break;
    }
    case Task::kPlanTargets:
      PlanTargetsChild(job, *data, *mesh, report, distance);
      break;
    case Task::kSamplePoints:
      SamplePointsChild(job, *data, *mesh, report, distance);
      break;
    case Task::kPathPair:
      PathPairChild(job, *mesh, report);
      break;
    case Task::kMatrix:
    case Task::kFields:
    case Task::kPathQueries:
      MatrixChild(job, *mesh, report, distance);
      break;
    case Task::kEstimate:
      EstimateChild(job, *data, *mesh, report, distance);
      break;
    case Task::kCgal: {
#ifdef GEODEX_BENCH_WITH_CGAL
      const std::vector<SurfacePoint> sources = AsSurfacePoints(job.sources);
      std::vector<double> solve, wall, cpu, setup, query;
      for (int r = 0; r < job.repeat; ++r) {
        distance.clear();
        distance.shrink_to_fit();
        CgalTiming timing;
        const auto start = std::chrono::steady_clock::now();
        const double cpu_start = CpuMs();
        distance = CgalDistances(*data, sources, &timing);
        cpu.push_back(CpuMs() - cpu_start);
        wall.push_back(MsSince(start));
        if (distance.empty()) {
          SetError(report, "CGAL refused the mesh (not a consistently oriented 2-manifold?)");
          break;
        }
        solve.push_back(timing.solve_ms);
        setup.push_back(timing.setup_ms);
        query.push_back(timing.query_ms);
      }
      report.runs = static_cast<int32_t>(solve.size());
      report.solve_ms = Median(solve);
      report.solve_ms_min = solve.empty() ? 0 : *std::min_element(solve.begin(), solve.end());
      report.wall_ms = Median(wall);
      report.cpu_ms = Median(cpu);
      report.cgal_setup_ms = Median(setup);
      report.cgal_query_ms = Median(query);
      if (!job.want_distances) distance.clear();
#else
      SetError(report, "built without CGAL");
#endif
      break;
    }
  }
  SendReport(fd, report, distance);
}

// Measurements run while other processes used >= 0.25 core, and all measurements.
int busy_measurements = 0, all_measurements = 0;
double max_other_load = 0;

// Reads `fd` into *out until EOF; kills `pid` and returns true once `timeout_s` since `start` has
// passed.
bool ReadUntilEof(int fd, pid_t pid, std::chrono::steady_clock::time_point start, double timeout_s,
                  std::string* out) {
  std::vector<char> buf(1 << 16);
  while (true) {
    const double left_ms = timeout_s * 1000 - MsSince(start);
    if (left_ms <= 0) {
      kill(pid, SIGKILL);
      return true;
    }
    struct pollfd p = {fd, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min(left_ms + 1, 60'000.0)));
    if (ready < 0 && errno != EINTR) return false;
    if (ready <= 0) continue;
    const ssize_t n = read(fd, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;  // EOF: the child has sent everything
    out->append(buf.data(), static_cast<size_t>(n));
  }
}

Outcome RunChild(const Job& job, double timeout_s, double wait_idle_s) {
  Outcome outcome;
  if (job.task != Task::kInfo) WaitForIdle(wait_idle_s);
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    outcome.message = absl::StrCat("pipe: ", std::strerror(errno));
    return outcome;
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const auto start = std::chrono::steady_clock::now();
  const double busy_start = MachineBusySeconds();
  const pid_t pid = fork();
  if (pid < 0) {
    outcome.message = absl::StrCat("fork: ", std::strerror(errno));
    close(fds[0]);
    close(fds[1]);
    return outcome;
  }
  if (pid == 0) {
    close(fds[0]);
    ChildMain(job, fds[1]);
    close(fds[1]);
    _exit(0);
  }
  close(fds[1]);
  std::string bytes;
  const bool timed_out = ReadUntilEof(fds[0], pid, start, timeout_s, &bytes);
  close(fds[0]);
  int status = 0;
  struct rusage usage;
  std::memset(&usage, 0, sizeof(usage));
  while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  outcome.elapsed_s = MsSince(start) / 1000;
  outcome.maxrss_kb = usage.ru_maxrss;
  const double child_cpu_s = usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 +
                             usage.ru_stime.tv_sec + usage.ru_stime.tv_usec * 1e-6;
  outcome.other_load = std::max(
      0.0, (MachineBusySeconds() - busy_start - child_cpu_s) / std::max(outcome.elapsed_s, 1e-3));
  if (job.task != Task::kInfo && outcome.elapsed_s >= 0.05) {
    // (Shorter runs are below /proc/stat's 10 ms resolution.)
    ++all_measurements;
    if (outcome.other_load >= 0.25) ++busy_measurements;
    max_other_load = std::max(max_other_load, outcome.other_load);
  }
  if (timed_out) {
    outcome.kind = Outcome::kTimeout;
    outcome.message = absl::StrFormat("timeout (killed after %g s)", timeout_s);
    return outcome;
  }
  if (bytes.size() < sizeof(ChildReport)) {
    outcome.kind = Outcome::kCrashed;
    if (WIFSIGNALED(status)) {
      const int sig = WTERMSIG(status);
      outcome.message = absl::StrCat("killed by signal ", sig, sig == SIGKILL ? " (OOM?)" : "");
    } else {
      outcome.message =
          absl::StrCat("child exited with status ", WEXITSTATUS(status), " without a report");
    }
    return outcome;
  }
  std::memcpy(&outcome.report, bytes.data(), sizeof(ChildReport));
  const uint64_t n = outcome.report.distance_count;
  if (bytes.size() != sizeof(ChildReport) + n * sizeof(double)) {
    outcome.kind = Outcome::kCrashed;
    outcome.message = "truncated report from the child";
    return outcome;
  }
  outcome.distance.resize(n);
  if (n > 0) std::memcpy(outcome.distance.data(), bytes.data() + sizeof(ChildReport), n * 8);
  if (outcome.report.ok) {
    outcome.kind = Outcome::kOk;
  } else {
    outcome.kind = outcome.report.resource_exhausted ? Outcome::kBudget : Outcome::kError;
    outcome.message = outcome.report.error;
  }
  return outcome;
}

// ------------------------------------------------------------------------------------------------
// Tables

class Table {
 public:
  // `align`: one 'l' (left) or 'r' (right) per column.
  Table(std::vector<std::string> headers, std::string align)
      : headers_(std::move(headers)), align_(std::move(align)) {
    align_.resize(headers_.size(), 'r');
  }

  void AddRow(std::vector<std::string> cells) {
    cells.resize(headers_.size());
    rows_.push_back(std::move(cells));
  }
  // A blank line in the text form (between meshes); ignored in Markdown.
  void AddBreak() { rows_.push_back({}); }
  bool empty() const { return rows_.empty(); }

  std::string Text() const {
    std::vector<size_t> width(headers_.size());
    for (size_t c = 0; c < headers_.size(); ++c) width[c] = headers_[c].size();
    for (const auto& row : rows_) {
      for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
    }
    auto line = [&](const std::vector<std::string>& cells) {
      std::string out;
      for (size_t c = 0; c < cells.size(); ++c) {
        const std::string pad(width[c] - cells[c].size(), ' ');
        if (c > 0) out += "  ";
        out += align_[c] == 'l' ? cells[c] + pad : pad + cells[c];
      }
      while (!out.empty() && out.back() == ' ') out.pop_back();
      return out + "\n";
    };
    std::string out = line(headers_);
    size_t total = 0;
    for (size_t w : width) total += w + 2;
    out += std::string(total - 2, '-') + "\n";
    for (const auto& row : rows_) out += row.empty() ? "\n" : line(row);
    return out;
  }

  std::string Markdown() const {
    std::string out = "| " + absl::StrJoin(headers_, " | ") + " |\n|";
    for (size_t c = 0; c < headers_.size(); ++c) {
      out += align_[c] == 'l' ? "---|" : "---:|";
    }
    out += "\n";
    for (const auto& row : rows_) {
      if (!row.empty()) out += "| " + absl::StrJoin(row, " | ") + " |\n";
    }
    return out;
  }

 private:
  std::vector<std::string> headers_;
  std::string align_;
  std::vector<std::vector<std::string>> rows_;
};

std::string Ms(double ms) {
  if (!(ms >= 0)) return "-";
  if (ms >= 1000) return absl::StrFormat("%.0f", ms);
  if (ms >= 100) return absl::StrFormat("%.1f", ms);
  if (ms >= 10) return absl::StrFormat("%.2f", ms);
  return absl::StrFormat("%.3f", ms);
}
std::string Ratio(double r) { return std::isfinite(r) ? absl::StrFormat("%.1fx", r) : "-"; }
std::string Count(uint64_t n) { return absl::StrCat(n); }
std::string MiBOfBytes(double bytes) { return absl::StrFormat("%.1f", bytes / kMiB); }
std::string MiBOfKb(int64_t kb) {
  const double mib = kb / 1024.0;
  return absl::StrFormat("%.1f", std::abs(mib) < 0.05 ? 0.0 : mib);  // no "-0.0"
}
std::string Sci(double x) { return std::isfinite(x) ? absl::StrFormat("%.1e", x) : "inf"; }

uint64_t FilteredWindows(const SolveStats& s) {
  return s.windows_filtered_at_creation + s.windows_filtered_at_pop + s.windows_filtered_overfilter;
}

// Differences between two per-vertex fields, over vertices where both are finite.
struct FieldDiff {
  double max_abs = 0;
  double max_rel = 0;            // max_abs / the largest finite reference distance
  double max_pointwise_rel = 0;  // max |a - b| / b over b > 0
  double mean_pointwise_rel = 0;
  uint64_t changed = 0;              // vertices with a != b
  uint64_t finiteness_mismatch = 0;  // finite in one, +inf in the other
  uint64_t below_reference = 0;      // a < b - 1e-12 * largest (for "a is an upper bound" checks)
};

FieldDiff Compare(const std::vector<double>& a, const std::vector<double>& reference) {
  FieldDiff d;
  if (a.size() != reference.size()) {
    d.max_abs = d.max_rel = kInf;
    return d;
  }
  double largest = 0;
  for (double b : reference) {
    if (std::isfinite(b)) largest = std::max(largest, b);
  }
  double rel_sum = 0;
  uint64_t rel_count = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const bool fa = std::isfinite(a[i]), fb = std::isfinite(reference[i]);
    if (fa != fb) {
      ++d.finiteness_mismatch;
      continue;
    }
    if (!fa) continue;
    const double diff = std::abs(a[i] - reference[i]);
    if (a[i] != reference[i]) ++d.changed;
    d.max_abs = std::max(d.max_abs, diff);
    if (a[i] < reference[i] - 1e-12 * largest) ++d.below_reference;
    if (reference[i] > 0) {
      const double rel = diff / reference[i];
      d.max_pointwise_rel = std::max(d.max_pointwise_rel, rel);
      rel_sum += rel;
      ++rel_count;
    }
  }
  d.max_rel = largest > 0 ? d.max_abs / largest : 0;
  d.mean_pointwise_rel = rel_count > 0 ? rel_sum / rel_count : 0;
  return d;
}

// ------------------------------------------------------------------------------------------------
// The runs

struct MeshInfo {
  std::string path, name;
  ChildReport report;       // from the baseline child
  int64_t baseline_rss_kb;  // its ru_maxrss: the loaded mesh, resident
  std::vector<uint32_t> sources;
};

int RepeatFor(const Config& config, const MeshInfo& mesh) {
  if (config.repeat > 0) return config.repeat;
  return mesh.report.faces < 100'000 ? 3 : 1;
}

std::string DeltaMiB(const Outcome& o, const MeshInfo& mesh) {
  return MiBOfKb(o.maxrss_kb - mesh.baseline_rss_kb);
}

void Progress(const std::string& what, const Outcome& o) {
  std::fprintf(stderr, "  %-40s %-16s %9.2f s  peak RSS %6.0f MiB  other load %.2f\n", what.c_str(),
               o.ok() ? "ok" : o.StatusText().c_str(), o.elapsed_s, o.maxrss_kb / 1024.0,
               o.other_load);
}

Outcome RunGeodex(const MeshInfo& mesh, const std::vector<uint32_t>& sources,
                  const GeodesicOptions& options, int repeat, bool want_distances,
                  const Config& config) {
  Job job;
  job.task = Task::kGeodex;
  job.path = mesh.path;
  job.sources = sources;
  job.options = options;
  job.repeat = repeat;
  job.want_distances = want_distances;
  return RunChild(job, config.timeout_s, config.wait_idle_s);
}

// VTP's single-source time over Dijkstra's, measured next to geodex on this machine kind
// (../shared/notes/anchors.md, 2026-11-24), by mesh name: the line to beat. 0 when unknown.
double AnchorVtpOverDijkstra(const std::string& mesh) {
  static const std::vector<std::pair<std::string, double>> anchors = {
      {"gargoyle", 36}, {"armadillo", 29}, {"jacksboro-terrain", 39}, {"dragon-vrip", 35}};
  for (const auto& [name, ratio] : anchors) {
    if (name == mesh) return ratio;
  }
  return 0;
}

// Runs a peer's command `COMMAND MESH SOURCE OUT` `repeat` times in its own process (exec'd by
// sh, so wait4's peak RSS is the peer's): the median of its ms=<value> lines is solve_ms, and the
// distances it wrote to OUT (raw doubles, one per file vertex) come back for comparison.
Outcome RunPeer(const std::string& command, const MeshInfo& mesh, uint32_t source, int repeat,
                const Config& config) {
  Outcome outcome;
  char out_path[] = "/tmp/geodex_bench_peer_XXXXXX";
  const int out_fd = mkstemp(out_path);
  if (out_fd < 0) {
    outcome.message = absl::StrCat("mkstemp: ", std::strerror(errno));
    return outcome;
  }
  close(out_fd);
  std::vector<double> times;
  for (int r = 0; r < repeat; ++r) {
    WaitForIdle(config.wait_idle_s);
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) break;
    const std::string line =
        absl::StrCat("exec ", command, " '", mesh.path, "' ", source, " '", out_path, "'");
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
      dup2(fds[1], STDOUT_FILENO);
      execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    std::string text;
    const bool timed_out = pid > 0 && ReadUntilEof(fds[0], pid, start, config.timeout_s, &text);
    close(fds[0]);
    int status = 0;
    struct rusage usage;
    std::memset(&usage, 0, sizeof usage);
    while (pid > 0 && wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
    }
    outcome.elapsed_s = MsSince(start) / 1000;
    outcome.maxrss_kb = std::max<int64_t>(outcome.maxrss_kb, usage.ru_maxrss);
    // The last line that starts with "ms=".
    size_t at = std::string::npos;
    for (size_t pos = text.find("ms="); pos != std::string::npos; pos = text.find("ms=", pos + 1)) {
      if (pos == 0 || text[pos - 1] == '\n') at = pos;
    }
    double ms = 0;
    if (timed_out) {
      outcome.kind = Outcome::kTimeout;
      outcome.message = absl::StrFormat("timeout (killed after %g s)", config.timeout_s);
      break;
    }
    if (pid < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || at == std::string::npos ||
        !absl::SimpleAtod(absl::string_view(text).substr(at + 3).substr(
                              0, text.find_first_of(" \n", at) - at - 3),
                          &ms)) {
      outcome.kind = Outcome::kCrashed;
      outcome.message = absl::StrCat("peer failed (status ", status, "): ", text.substr(0, 200));
      break;
    }
    times.push_back(ms);
  }
  if (!times.empty() && static_cast<int>(times.size()) == repeat) {
    outcome.kind = Outcome::kOk;
    outcome.report.ok = 1;
    outcome.report.runs = repeat;
    outcome.report.solve_ms = Median(times);
    outcome.report.wall_ms = outcome.report.solve_ms;
    std::ifstream in(out_path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    outcome.distance.resize(bytes.size() / sizeof(double));
    std::memcpy(outcome.distance.data(), bytes.data(), outcome.distance.size() * sizeof(double));
    for (double& d : outcome.distance) {
      if (!(d < 1e300)) d = kInf;  // peers mark unreachable vertices in their own ways
    }
  }
  unlink(out_path);
  return outcome;
}

// Below 50 ms the /proc/stat sample (10 ms ticks) says nothing.
std::string OtherLoad(const Outcome& o) {
  return o.elapsed_s >= 0.05 ? absl::StrFormat("%.2f", o.other_load) : "-";
}

std::string Notes(const std::vector<std::string>& notes) {
  std::string out;
  for (const std::string& n : notes) out += "- " + n + "\n";
  return out;
}

struct Section {
  std::string title;
  std::string intro;
  Table table;
  std::vector<std::string> notes;
};

Section MeshSection(const std::vector<MeshInfo>& meshes) {
  Section s{"Meshes",
            "Baseline child per mesh: read + TriangleMesh::Build, nothing else. \"resident\" is "
            "the RSS once loaded (the baseline subtracted from every measurement), \"load peak\" "
            "the high-water mark while loading.",
            Table({"mesh", "vertices", "faces", "components", "largest comp. faces", "saddles",
                   "boundary vertices", "sources", "load ms", "resident MiB", "load peak MiB"},
                  "lrrrrrrlrrr"),
            {}};
  for (const MeshInfo& m : meshes) {
    s.table.AddRow({m.name, Count(m.report.file_vertices), Count(m.report.faces),
                    Count(m.report.components), Count(m.report.largest_component_faces),
                    Count(m.report.saddles), Count(m.report.boundary_vertices),
                    absl::StrJoin(m.sources, ", "), Ms(m.report.load_ms),
                    MiBOfKb(m.baseline_rss_kb), MiBOfKb(m.report.load_peak_kb)});
    if (!m.report.hiwater_reset) {
      s.notes.push_back(absl::StrCat(m.name,
                                     ": /proc/self/clear_refs could not reset the RSS "
                                     "high-water mark; RSS peaks include the load peak"));
    }
  }
  return s;
}

Section MainSection(const Config& config, const std::vector<MeshInfo>& meshes) {
  Section s{"ICH vs Dijkstra vs CGAL",
            "solve ms: median of the repeats, propagation only (SolveStats.solve_ms; for CGAL "
            "build_sequence_tree()). wall ms: the whole call (source setup, result arrays; for "
            "CGAL also building its Surface_mesh, reading the distances back and destroying its "
            "sequence tree). cpu ms: CPU time of the whole call (immune to time slicing, not to "
            "a busy sibling core). x Dijkstra = solve ms / Dijkstra's solve ms; CGAL/ICH = "
            "CGAL's solve ms / ICH's. filtered = Lemma 2 filter removals (at creation + at pop + "
            "lambda over-filter). peak MiB = SolveStats.peak_bytes. RSS MiB = the child's peak "
            "resident size while solving (mesh included); delta = RSS minus the mesh-only "
            "baseline child. vs CGAL abs / rel: max |ICH - CGAL| over all vertices, and that "
            "divided by the largest distance. other load: cores used by other processes during "
            "the measurement (from /proc/stat; near 1 on a 2-core machine, the times are "
            "unreliable).",
            Table({"mesh",       "faces",         "source",          "method",
                   "R",          "solve ms",      "wall ms",         "cpu ms",
                   "x Dijkstra", "CGAL/ICH",      "windows created", "filtered",
                   "processed",  "max level",     "peak live",       "peak MiB",
                   "RSS MiB",    "delta RSS MiB", "vs CGAL abs",     "vs CGAL rel",
                   "other load"},
                  "lrrl"),
            {}};
  bool first = true;
  for (const MeshInfo& mesh : meshes) {
    const int repeat = RepeatFor(config, mesh);
    const bool cgal = config.run_cgal && mesh.report.faces <= config.cgal_max_faces;
    for (uint32_t source : mesh.sources) {
      if (!first) s.table.AddBreak();
      first = false;
      const std::vector<uint32_t> src = {source};
      std::fprintf(stderr, "%s (%llu faces), source %u, R = %d\n", mesh.name.c_str(),
                   static_cast<unsigned long long>(mesh.report.faces), source, repeat);
      std::optional<Outcome> dijkstra, ich, paper, cgal_run;
      std::vector<std::pair<std::string, Outcome>> peer_runs;
      if (config.run_dijkstra) {
        GeodesicOptions options;
        options.method = Method::kDijkstra;
        dijkstra = RunGeodex(mesh, src, options, repeat, config.run_ich, config);
        Progress("dijkstra", *dijkstra);
      }
      if (config.run_ich) {
        ich = RunGeodex(mesh, src, GeodesicOptions{}, repeat, true, config);
        Progress("exact", *ich);
      }
      if (config.run_paper) {
        GeodesicOptions options;
        options.method = Method::kIch;
        paper = RunGeodex(mesh, src, options, repeat, true, config);
        Progress("ich (paper)", *paper);
      }
      for (const auto& [name, command] : config.peers) {
        peer_runs.emplace_back(name, RunPeer(command, mesh, source, repeat, config));
        Progress(name, peer_runs.back().second);
      }
#ifdef GEODEX_BENCH_WITH_CGAL
      if (cgal) {
        Job job;
        job.task = Task::kCgal;
        job.path = mesh.path;
        job.sources = src;
        job.repeat = repeat;
        job.want_distances = config.run_ich;
        cgal_run = RunChild(job, config.timeout_s, config.wait_idle_s);
        Progress("cgal", *cgal_run);
      }
#endif
      const double dijkstra_ms =
          dijkstra && dijkstra->ok() ? dijkstra->report.solve_ms : std::nan("");
      const double cgal_ms = cgal_run && cgal_run->ok() ? cgal_run->report.solve_ms : std::nan("");
      auto row = [&](const std::string& method, const Outcome& o) {
        std::vector<std::string> cells = {mesh.name, Count(mesh.report.faces), Count(source),
                                          method, Count(repeat)};
        if (!o.ok()) {
          cells.push_back(o.StatusText());
          for (int i = 0; i < 11; ++i) cells.push_back("");
          cells.push_back(MiBOfKb(o.maxrss_kb));
          cells.push_back(DeltaMiB(o, mesh));
          cells.insert(cells.end(), {"", "", OtherLoad(o)});
          if (!o.message.empty()) {
            s.notes.push_back(
                absl::StrCat(mesh.name, " source ", source, " ", method, ": ", o.message));
          }
          return cells;
        }
        const ChildReport& r = o.report;
        const bool windows = method == "exact" || method == "ICH (paper)";
        cells.push_back(Ms(r.solve_ms));
        cells.push_back(Ms(r.wall_ms));
        cells.push_back(Ms(r.cpu_ms));
        cells.push_back(Ratio(r.solve_ms / dijkstra_ms));
        cells.push_back(method != "Dijkstra" && method != "CGAL" ? Ratio(cgal_ms / r.solve_ms)
                                                                 : "");
        cells.push_back(windows ? Count(r.stats.windows_created) : "");
        cells.push_back(windows ? Count(FilteredWindows(r.stats)) : "");
        cells.push_back(windows ? Count(r.stats.windows_processed) : "");
        cells.push_back(windows ? Count(r.stats.max_level) : "");
        cells.push_back(windows ? Count(r.stats.peak_live_windows) : "");
        cells.push_back(windows || method == "Dijkstra"
                            ? MiBOfBytes(static_cast<double>(r.stats.peak_bytes))
                            : "");
        cells.push_back(MiBOfKb(o.maxrss_kb));
        cells.push_back(DeltaMiB(o, mesh));
        cells.insert(cells.end(), {"", "", OtherLoad(o)});
        return cells;
      };
      if (dijkstra) s.table.AddRow(row("Dijkstra", *dijkstra));
      // An exact method's row, with its difference from CGAL (or, without CGAL, from geodex's
      // default engine) and a check against Dijkstra's upper bound.
      auto exact_row = [&](const std::string& method, const Outcome& o) {
        std::vector<std::string> cells = row(method, o);
        const Outcome* reference = cgal_run && cgal_run->ok()        ? &*cgal_run
                                   : ich && ich->ok() && &o != &*ich ? &*ich
                                                                     : nullptr;
        if (o.ok() && reference != nullptr && o.distance.size() == reference->distance.size()) {
          const FieldDiff d = Compare(o.distance, reference->distance);
          cells[cells.size() - 3] = Sci(d.max_abs);
          cells[cells.size() - 2] = Sci(d.max_rel);
          if (reference != &*cgal_run) {
            cells[cells.size() - 3] += " (vs exact)";
          }
          if (d.finiteness_mismatch > 0) {
            s.notes.push_back(absl::StrCat(mesh.name, " source ", source, " ", method, ": ",
                                           d.finiteness_mismatch,
                                           " vertices finite in only one of it and the reference"));
          }
        }
        if (o.ok() && dijkstra && dijkstra->ok() &&
            o.distance.size() == dijkstra->distance.size()) {
          // Dijkstra's edge paths are real paths: exact distances can only be shorter or equal.
          const FieldDiff d = Compare(dijkstra->distance, o.distance);
          if (d.below_reference > 0) {
            s.notes.push_back(absl::StrCat(mesh.name, " source ", source, ": ", method,
                                           " exceeds Dijkstra at ", d.below_reference,
                                           " vertices (not exact there)"));
          }
        }
        s.table.AddRow(cells);
      };
      if (ich) exact_row("exact", *ich);
      if (paper) exact_row("ICH (paper)", *paper);
      for (const auto& [name, o] : peer_runs) {
        exact_row(name, o);
        if (o.ok() && ich && ich->ok()) {
          s.notes.push_back(absl::StrFormat(
              "%s source %u: geodex exact / %s = %.2f in time, %.2f in peak RSS", mesh.name, source,
              name, ich->report.solve_ms / o.report.solve_ms,
              static_cast<double>(ich->maxrss_kb) / std::max<int64_t>(1, o.maxrss_kb)));
        }
      }
      if (const double vtp = AnchorVtpOverDijkstra(mesh.name); vtp > 0 && ich && ich->ok()) {
        s.notes.push_back(absl::StrFormat(
            "%s: the line to beat, VTP at %.0fx Dijkstra (../shared/notes/anchors.md); geodex "
            "exact here at %.1fx",
            mesh.name, vtp, ich->report.solve_ms / dijkstra_ms));
      }
      if (cgal_run) {
        s.table.AddRow(row("CGAL", *cgal_run));
        if (cgal_run->ok()) {
          s.notes.push_back(absl::StrFormat(
              "%s source %u CGAL: setup %s ms + build_sequence_tree %s ms + query %s ms", mesh.name,
              source, Ms(cgal_run->report.cgal_setup_ms), Ms(cgal_run->report.solve_ms),
              Ms(cgal_run->report.cgal_query_ms)));
        }
      }
    }
    if (config.run_cgal && !cgal) {
      s.notes.push_back(absl::StrFormat("%s: CGAL not run (%d faces > --cgal-max-faces %d)",
                                        mesh.name, mesh.report.faces, config.cgal_max_faces));
    }
  }
  return s;
}

Section AblationSection(const Config& config, const std::vector<MeshInfo>& meshes) {
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
  return s;
}

Section LambdaSection(const Config& config, const std::vector<MeshInfo>& meshes) {
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
  return s;
}

// ------------------------------------------------------------------------------------------------
// Targeted queries: the parent's side

// The meshes a targeted-query mode runs on: all given --mesh files, else its defaults.
std::vector<const MeshInfo*> ModeMeshes(const Config& config, const std::vector<MeshInfo>& meshes,
                                        const std::vector<std::string>& defaults) {
  std::vector<const MeshInfo*> out;
  for (const MeshInfo& m : meshes) {
    if (!config.mesh_files.empty() ||
        std::find(defaults.begin(), defaults.end(), m.name) != defaults.end()) {
      out.push_back(&m);
    }
  }
  return out;
}

Outcome RunPointJob(const MeshInfo& mesh, Job job, const Config& config) {
  job.path = mesh.path;
  return RunChild(job, config.timeout_s, config.wait_idle_s);
}

// The value at the nearest rank q (0 < q <= 1) of v.
double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size(), std::max<size_t>(rank, 1)) - 1];
}

double MaxOf(const std::vector<double>& v) {
  return v.empty() ? std::nan("") : *std::max_element(v.begin(), v.end());
}
double MinOf(const std::vector<double>& v) {
  return v.empty() ? std::nan("") : *std::min_element(v.begin(), v.end());
}

// |a - b| / |b|, 0 when both are equal (also both infinite).
double RelDiff(double a, double b) {
  if (a == b) return 0;
  return std::abs(a - b) / std::abs(b);
}

std::string Percent(double fraction) {
  if (!std::isfinite(fraction)) return "-";
  if (fraction == 0) return "0";
  return absl::StrFormat("%.3g%%", 100 * fraction);
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

std::vector<Section> AstarSections(const Config& config, const std::vector<MeshInfo>& meshes) {
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

Section MatrixSection(const Config& config, const std::vector<MeshInfo>& meshes) {
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
  return s;
}

Section EstimateSection(const Config& config, const std::vector<MeshInfo>& meshes) {
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
  return s;
}

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
      for (const auto& entry : std::filesystem::directory_iterator(config.meshes_dir, error)) {
        if (entry.is_regular_file() && IsMeshFileName(entry.path().filename().string())) {
          paths.push_back(entry.path().lexically_normal().string());
        }
      }
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
      UtcNow(), GitDescription(), GEODEX_BUILD_TYPE, CpuModel(), UsableCpus(), LoadAverage());
  std::printf("%s\n", header.c_str());
#ifndef NDEBUG
  std::printf("WARNING: assertions are on (not a Release build): times are not representative\n");
#endif
#ifndef GEODEX_BENCH_WITH_CGAL
  std::printf("note: built without CGAL: no CGAL column\n");
#endif

  std::vector<MeshInfo> meshes;
  for (const std::string& path : paths) {
    Job job;
    job.task = Task::kInfo;
    job.path = path;
    job.sources_wanted = config.sources;
    const Outcome o = RunChild(job, config.timeout_s, 0);
    if (!o.ok()) {
      std::printf("skipping %s: %s\n", path.c_str(),
                  o.message.empty() ? o.StatusText().c_str() : o.message.c_str());
      continue;
    }
    MeshInfo info;
    info.path = path;
    info.name = MeshName(path);
    info.report = o.report;
    info.baseline_rss_kb = o.maxrss_kb;
    info.sources.assign(o.report.sources, o.report.sources + o.report.source_count);
    meshes.push_back(std::move(info));
  }
  std::sort(meshes.begin(), meshes.end(), [](const MeshInfo& a, const MeshInfo& b) {
    return a.report.faces != b.report.faces ? a.report.faces < b.report.faces : a.name < b.name;
  });

  std::vector<Section> sections;
  sections.push_back(MeshSection(meshes));
  if (!config.ablation && !config.lambda && !PointQueryMode(config)) {
    sections.push_back(MainSection(config, meshes));
  }
  if (config.ablation) sections.push_back(AblationSection(config, meshes));
  if (config.lambda) sections.push_back(LambdaSection(config, meshes));
  if (config.astar) {
    for (Section& s : AstarSections(config, meshes)) sections.push_back(std::move(s));
  }
  if (config.matrix) sections.push_back(MatrixSection(config, meshes));
  if (config.estimate) sections.push_back(EstimateSection(config, meshes));

  const std::string footer = absl::StrFormat(
      "load average at the end: %s; %d of %d measurements (of 50 ms or more) ran while other "
      "processes used a quarter of a core or more (at most %.2f cores)",
      LoadAverage(), busy_measurements, all_measurements, max_other_load);
  std::string markdown = absl::StrCat("<!-- ", header, " -->\n");
  for (const Section& s : sections) {
    std::printf("\n== %s ==\n%s\n\n%s", s.title.c_str(), s.intro.c_str(), s.table.Text().c_str());
    if (!s.notes.empty()) std::printf("\n%s", Notes(s.notes).c_str());
    absl::StrAppend(&markdown, "\n### ", s.title, "\n\n", s.intro, "\n\n", s.table.Markdown());
    if (!s.notes.empty()) absl::StrAppend(&markdown, "\n", Notes(s.notes));
  }
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
}  // namespace geodex

int main(int argc, char** argv) { return geodex::Main(argc, argv); }
