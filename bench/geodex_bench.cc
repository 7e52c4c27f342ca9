// geodex_bench: times our exact ICH, Dijkstra on the edge graph and (when built with CGAL)
// CGAL's Surface_mesh_shortest_path from the same sources in one run, and reports window counts,
// memory and the ICH-vs-CGAL difference. Two extra modes: --ablation (Lemma 1 / Lemma 2 on and
// off) and --lambda (the precision knob of section 7 of Xin & Wang 2010).
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
#include "geodex/geodesic_solver.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"
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
  bool run_ich = true, run_dijkstra = true, run_cgal = true;
  std::string markdown;
  double timeout_s = 300;
  double wait_idle_s = 0;
  bool ablation = false;
  bool lambda = false;
};

constexpr char kUsage[] =
    "usage: geodex_bench [--meshes DIR] [--mesh FILE ...] [--sources N] [--repeat R]\n"
    "                    [--cgal-max-faces F] [--methods ich,dijkstra,cgal] [--markdown OUT.md]\n"
    "                    [--timeout-s T] [--wait-idle S] [--ablation] [--lambda]\n"
    "\n"
    "  --meshes DIR        every mesh file in DIR (.off .obj .ply .stl, optionally .gz); default\n"
    "                      ../shared/meshes next to the source tree, unless --mesh is given\n"
    "  --mesh FILE         a mesh file (repeatable; added to --meshes DIR when both are given)\n"
    "  --sources N         single-source runs per mesh (default 2): vertex 0, then the smallest\n"
    "                      vertex id >= V/2 in the largest component, then >= V/4, 3V/4, V/8, ...\n"
    "  --repeat R          repeats per measurement, the median is reported (default: 3 below\n"
    "                      100k faces, 1 above)\n"
    "  --cgal-max-faces F  run CGAL only on meshes with at most F faces (default 100000)\n"
    "  --methods LIST      any of ich,dijkstra,cgal (default all)\n"
    "  --markdown OUT.md   also write the tables as Markdown\n"
    "  --timeout-s T       kill a measurement after T seconds (default 300)\n"
    "  --wait-idle S       before each measurement wait up to S seconds until the other\n"
    "                      processes use less than a quarter of a core (default 0: no wait)\n"
    "  --ablation          instead of the main table: ICH with the filter (Lemma 2) and one angle\n"
    "                      one split (Lemma 1) on/off, on each given mesh\n"
    "  --lambda            instead of the main table: lambda in {0 .. 1} x {max edge, mean edge}\n";

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
    } else if (arg == "--meshes" || arg == "--mesh" || arg == "--sources" || arg == "--repeat" ||
               arg == "--cgal-max-faces" || arg == "--methods" || arg == "--markdown" ||
               arg == "--timeout-s" || arg == "--wait-idle") {
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
      } else if (arg == "--methods") {
        config.run_ich = config.run_dijkstra = config.run_cgal = false;
        for (absl::string_view m : absl::StrSplit(*v, ',', absl::SkipEmpty())) {
          if (m == "ich") {
            config.run_ich = true;
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
// Child processes

enum class Task : int32_t { kInfo, kGeodex, kCgal };

// What a child does. `options` is used by kGeodex (its method picks ICH or Dijkstra).
struct Job {
  Task task = Task::kInfo;
  std::string path;
  int sources_wanted = 2;         // kInfo
  std::vector<uint32_t> sources;  // file vertex ids, one multi-source solve (one id: one source)
  GeodesicOptions options;
  int repeat = 1;
  bool want_distances = false;
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
  uint64_t distance_count = 0;
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
  bool timed_out = false;
  std::vector<char> buf(1 << 16);
  while (true) {
    const double left_ms = timeout_s * 1000 - MsSince(start);
    if (left_ms <= 0) {
      timed_out = true;
      kill(pid, SIGKILL);
      break;
    }
    struct pollfd p = {fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min(left_ms + 1, 60'000.0)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t n = read(fds[0], buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // EOF: the child has sent everything
    bytes.append(buf.data(), static_cast<size_t>(n));
  }
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
      std::optional<Outcome> dijkstra, ich, cgal_run;
      if (config.run_dijkstra) {
        GeodesicOptions options;
        options.method = Method::kDijkstra;
        dijkstra = RunGeodex(mesh, src, options, repeat, config.run_ich, config);
        Progress("dijkstra", *dijkstra);
      }
      if (config.run_ich) {
        ich = RunGeodex(mesh, src, GeodesicOptions{}, repeat, cgal || config.run_dijkstra, config);
        Progress("ich", *ich);
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
      const double ich_ms = ich && ich->ok() ? ich->report.solve_ms : std::nan("");
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
        const bool windows = method == "ICH";
        cells.push_back(Ms(r.solve_ms));
        cells.push_back(Ms(r.wall_ms));
        cells.push_back(Ms(r.cpu_ms));
        cells.push_back(Ratio(r.solve_ms / dijkstra_ms));
        cells.push_back(windows ? Ratio(cgal_ms / ich_ms) : "");
        cells.push_back(windows ? Count(r.stats.windows_created) : "");
        cells.push_back(windows ? Count(FilteredWindows(r.stats)) : "");
        cells.push_back(windows ? Count(r.stats.windows_processed) : "");
        cells.push_back(windows ? Count(r.stats.max_level) : "");
        cells.push_back(windows ? Count(r.stats.peak_live_windows) : "");
        cells.push_back(method == "CGAL" ? ""
                                         : MiBOfBytes(static_cast<double>(r.stats.peak_bytes)));
        cells.push_back(MiBOfKb(o.maxrss_kb));
        cells.push_back(DeltaMiB(o, mesh));
        cells.insert(cells.end(), {"", "", OtherLoad(o)});
        return cells;
      };
      if (dijkstra) s.table.AddRow(row("Dijkstra", *dijkstra));
      if (ich) {
        std::vector<std::string> cells = row("ICH", *ich);
        if (ich->ok() && cgal_run && cgal_run->ok()) {
          const FieldDiff d = Compare(ich->distance, cgal_run->distance);
          cells[cells.size() - 3] = Sci(d.max_abs);
          cells[cells.size() - 2] = Sci(d.max_rel);
          if (d.finiteness_mismatch > 0) {
            s.notes.push_back(absl::StrCat(mesh.name, " source ", source, ": ",
                                           d.finiteness_mismatch,
                                           " vertices finite in one of ICH/CGAL only"));
          }
        }
        if (ich->ok() && dijkstra && dijkstra->ok()) {
          // Dijkstra's edge paths are real paths: exact distances can only be shorter or equal.
          const FieldDiff d = Compare(dijkstra->distance, ich->distance);
          if (d.below_reference > 0) {
            s.notes.push_back(absl::StrCat(mesh.name, " source ", source,
                                           ": ICH exceeds Dijkstra at ", d.below_reference,
                                           " vertices (not exact there)"));
          }
        }
        s.table.AddRow(cells);
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
  for (const std::string& f : config.mesh_files) paths.push_back(f);
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
  if (!config.ablation && !config.lambda) sections.push_back(MainSection(config, meshes));
  if (config.ablation) sections.push_back(AblationSection(config, meshes));
  if (config.lambda) sections.push_back(LambdaSection(config, meshes));

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
  return 0;
}

}  // namespace
}  // namespace geodex

int main(int argc, char** argv) { return geodex::Main(argc, argv); }
