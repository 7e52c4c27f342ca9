#include "child_tasks.h"

#include <malloc.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <optional>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "geodex/distance_field.h"
#include "geodex/mesh_io.h"
#include "harness/child_runner.h"
#include "harness/machine.h"
#include "harness/peak_memory.h"
#include "harness/stats.h"

namespace geodex::bench {
namespace {

void SendReport(int fd, ChildReport& report, const std::vector<double>& distance) {
  report.distance_count = distance.size();
  std::string bytes(sizeof(report) + distance.size() * sizeof(double), '\0');
  std::memcpy(bytes.data(), &report, sizeof(report));
  if (!distance.empty()) {
    std::memcpy(bytes.data() + sizeof(report), distance.data(), distance.size() * sizeof(double));
  }
  WriteAll(fd, bytes.data(), bytes.size());
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

// kGeodex: ComputeDistanceField from job.sources with job.options, `repeat` times; the last
// field's distances go back when job.want_distances.
void GeodexChild(const Job& job, const TriangleMesh& mesh, ChildReport& report,
                 std::vector<double>& distance) {
  const std::vector<SurfacePoint> sources = AsSurfacePoints(job.sources);
  std::vector<double> solve, wall, cpu;
  std::optional<DistanceField> field;
  for (int r = 0; r < job.repeat; ++r) {
    field.reset();  // never two fields alive at once
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = CpuMs();
    absl::StatusOr<DistanceField> result = ComputeDistanceField(mesh, sources, job.options);
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
    case Task::kGeodex:
      GeodexChild(job, *mesh, report, distance);
      break;
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
    case Task::kCgal:
      CgalChild(job, *data, report, distance);
      break;
  }
  SendReport(fd, report, distance);
}

}  // namespace

void SetError(ChildReport& report, const std::string& message) {
  report.ok = 0;
  std::snprintf(report.error, sizeof(report.error), "%s", message.c_str());
}

std::vector<SurfacePoint> AsSurfacePoints(const std::vector<uint32_t>& ids) {
  std::vector<SurfacePoint> points;
  for (uint32_t v : ids) points.push_back(SurfacePoint::AtVertex(v));
  return points;
}

Outcome RunChild(const Job& job, double timeout_s, double wait_idle_s) {
  Outcome outcome;
  ChildOptions options;
  options.timeout_s = timeout_s;
  options.measurement = job.task != Task::kInfo;
  options.wait_idle_s = wait_idle_s;
  const ChildRun run = RunInChild([&job](int fd) { ChildMain(job, fd); }, options);
  if (!run.started) {
    outcome.message = run.error;
    return outcome;
  }
  const std::string& bytes = run.bytes;
  const int status = run.status;
  outcome.elapsed_s = run.elapsed_s;
  outcome.maxrss_kb = run.maxrss_kb;
  outcome.other_load = run.other_load;
  if (run.timed_out) {
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

}  // namespace geodex::bench
