#pragma once

// What a forked child measures (bench/harness/child_runner.h runs it): a Job goes in, a
// ChildReport (plain data, sent as bytes through the pipe) and some doubles come back, and the
// parent sees an Outcome. Every child loads the mesh itself, resets its RSS high-water mark once
// loaded, then runs its task; the tasks of one section are defined in that section's file.

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "config.h"
#include "geodex/geodesic_solver.h"
#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex::bench {

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

// Runs `job` in its own child (killed after `timeout_s`); a job other than kInfo is a measurement:
// it first waits up to `wait_idle_s` for an idle machine.
Outcome RunChild(const Job& job, double timeout_s, double wait_idle_s);

// For the tasks: marks the report failed with `message`.
void SetError(ChildReport& report, const std::string& message);
// File vertex ids as vertex points.
std::vector<SurfacePoint> AsSurfacePoints(const std::vector<uint32_t>& ids);

// The tasks of the sections, run in the child on the loaded mesh; `values` are the doubles sent
// back after the report.
// kCgal (engine_table.cc): CGAL's distances from job.sources, `repeat` times.
void CgalChild(const Job& job, const MeshData& data, ChildReport& report,
               std::vector<double>& values);
// kPlanTargets and kPathPair (astar.cc).
void PlanTargetsChild(const Job& job, const MeshData& data, const TriangleMesh& mesh,
                      ChildReport& report, std::vector<double>& values);
void PathPairChild(const Job& job, const TriangleMesh& mesh, ChildReport& report);
// kSamplePoints, kMatrix, kFields and kPathQueries (matrix.cc).
void SamplePointsChild(const Job& job, const MeshData& data, const TriangleMesh& mesh,
                       ChildReport& report, std::vector<double>& values);
void MatrixChild(const Job& job, const TriangleMesh& mesh, ChildReport& report,
                 std::vector<double>& values);
// kEstimate (estimate.cc).
void EstimateChild(const Job& job, const MeshData& data, const TriangleMesh& mesh,
                   ChildReport& report, std::vector<double>& values);

}  // namespace geodex::bench
