#include "cli_commands.h"
#include "cli_common.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <set>

#include <unistd.h>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/locate.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/mesh_io.h"
#include "geodex/samples.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex::cli {

bool ParseArgs(int argc, char** argv, int first, const std::vector<std::string>& boolean_flags,
               Args* out, std::string* error) {
  const std::set<std::string> booleans(boolean_flags.begin(), boolean_flags.end());
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) != 0 || a == "--") {
      out->positional.push_back(a);
      continue;
    }
    a = a.substr(2);
    const size_t eq = a.find('=');
    if (eq != std::string::npos) {
      out->options[a.substr(0, eq)] = a.substr(eq + 1);
    } else if (booleans.count(a)) {
      out->options[a] = "";
    } else if (i + 1 < argc) {
      out->options[a] = argv[++i];
    } else {
      *error = absl::StrFormat("option --%s needs a value", a);
      return false;
    }
  }
  return true;
}

int RunInfo(const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"format", "strict"}, &error)) return Fail(kExitUsage, error);
  if (args.positional.size() != 1) return Fail(kExitUsage, "usage: geodex info MESH [--format json]");
  const std::string format = args.options.count("format") ? args.options.at("format") : "text";
  if (format != "text" && format != "json") {
    return Fail(kExitUsage, "--format must be text or json");
  }
  MeshBuildOptions options;
  options.strict = args.options.count("strict") > 0;
  absl::StatusOr<LoadedMesh> loaded = LoadMesh(args.positional[0], options);
  if (!loaded.ok()) return Fail(kExitInput, std::string(loaded.status().message()));
  const TriangleMesh& mesh = loaded->mesh;
  const MeshReport& r = mesh.report();
  InfoValues v;
  v.report = r;
  v.internal_vertices = mesh.vertex_count();
  v.mean_edge_length = mesh.MeanEdgeLength();
  v.max_edge_length = mesh.MaxEdgeLength();
  v.bbox_min = mesh.BoundsMin();
  v.bbox_max = mesh.BoundsMax();
  v.bytes = mesh.MemoryBytes();
  v.load_ms = loaded->load_ms;
  v.build_ms = loaded->build_ms;
  std::fputs(FormatInfo(v, format == "json").c_str(), stdout);
  return kExitOk;
}

// --lambda, --lambda-scale, --max-distance and --max-windows, shared by distances, path and matrix.
bool GetSolverFlags(const Args& args, GeodesicOptions* options, std::string* error) {
  if (!GetDouble(args, "lambda", &options->lambda, error) ||
      !GetDouble(args, "max-distance", &options->max_distance, error) ||
      !GetUint(args, "max-windows", &options->max_windows, error)) {
    return false;
  }
  if (!(options->lambda >= 0 && options->lambda <= 1)) {
    *error = absl::StrFormat("--lambda must be in [0, 1], got %g", options->lambda);
    return false;
  }
  if (!(options->max_distance > 0)) {
    *error = "--max-distance must be positive";
    return false;
  }
  if (args.options.count("lambda-scale")) {
    const std::string& s = args.options.at("lambda-scale");
    if (s == "max") {
      options->lambda_scale = LambdaScale::kMaxEdge;
    } else if (s == "mean") {
      options->lambda_scale = LambdaScale::kMeanEdge;
    } else {
      *error = "--lambda-scale must be max or mean";
      return false;
    }
  }
  return true;
}

int RunDistances(const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"sources", "method", "lambda", "lambda-scale", "max-distance",
                         "max-windows", "stats", "output", "no-filter", "no-one-split", "at"},
                  &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources")) {
    return Fail(kExitUsage, "usage: geodex distances MESH --sources SPEC [options]");
  }
  GeodesicOptions options;
  const std::string method = args.options.count("method") ? args.options.at("method") : "exact";
  if (method == "exact") {
    options.method = Method::kExact;
  } else if (method == "ich") {
    options.method = Method::kIch;
  } else if (method == "dijkstra") {
    options.method = Method::kDijkstra;
  } else {
    return Fail(kExitUsage, "--method must be exact, ich or dijkstra");
  }
  if (!GetSolverFlags(args, &options, &error)) return Fail(kExitUsage, error);
  options.use_filter = !args.options.count("no-filter");
  options.use_one_angle_one_split = !args.options.count("no-one-split");

  absl::StatusOr<std::vector<SurfacePoint>> sources = ParseSurfacePoints(args.options.at("sources"));
  if (!sources.ok()) return Fail(kExitUsage, "--sources: " + std::string(sources.status().message()));
  absl::StatusOr<LoadedMesh> loaded = LoadMesh(args.positional[0], MeshBuildOptions{});
  if (!loaded.ok()) return Fail(kExitInput, std::string(loaded.status().message()));
  std::unique_ptr<SurfaceLocator> locator;
  if (!ResolvePoints(loaded->mesh, "sources", &*sources, &locator, &error)) {
    return Fail(kExitUsage, error);
  }
  absl::StatusOr<DistanceField> field = ComputeDistanceField(loaded->mesh, *sources, options);
  if (!field.ok()) {
    const int code = field.status().code() == absl::StatusCode::kInvalidArgument ? kExitUsage
                                                                                  : kExitSolveFailed;
    return Fail(code, std::string(field.status().message()));
  }
  const auto t_out = std::chrono::steady_clock::now();
  std::string text;
  if (args.options.count("at")) {
    // Surface points: the unfolding estimate and the exact value, one line each.
    absl::StatusOr<std::vector<SurfacePoint>> at = ParseSurfacePoints(args.options.at("at"));
    if (!at.ok()) return Fail(kExitUsage, "--at: " + std::string(at.status().message()));
    if (!ResolvePoints(loaded->mesh, "at", &*at, &locator, &error)) return Fail(kExitUsage, error);
    absl::StatusOr<std::vector<std::pair<double, uint32_t>>> exact =
        ComputeExactDistancesAt(loaded->mesh, *sources, *at, options);
    if (!exact.ok()) return Fail(kExitSolveFailed, std::string(exact.status().message()));
    for (size_t i = 0; i < at->size(); ++i) {
      absl::StatusOr<PointEstimate> est = EstimateDistanceAt(loaded->mesh, *field, (*at)[i]);
      if (!est.ok()) return Fail(kExitUsage, "--at: " + std::string(est.status().message()));
      text += FormatAtLine((*at)[i], est->distance, (*exact)[i].first, (*exact)[i].second);
    }
  } else {
    text = FormatDistances(field->distance);
  }
  if (int code = WriteOutput(args, text); code != kExitOk) return code;
  if (args.options.count("stats")) {
    const SolveStats& s = field->stats;
    std::fprintf(
        stderr,
        "{\"method\": \"%s\", \"vertices\": %u, \"faces\": %u, \"sources\": %zu, "
        "\"windows_created\": %llu, \"windows_filtered_at_creation\": %llu, "
        "\"windows_filtered_at_pop\": %llu, \"windows_filtered_overfilter\": %llu, "
        "\"children_skipped_one_split\": %llu, \"windows_deleted_one_split\": %llu, "
        "\"windows_processed\": %llu, \"pseudo_sources\": %llu, \"pseudo_sources_full_fan\": %llu, "
        "\"pseudo_sources_shadow_only\": %llu, \"edge_relaxations\": %llu, "
        "\"max_level\": %u, \"peak_live_windows\": %llu, \"peak_bytes\": %llu, "
        "\"mesh_bytes\": %llu, \"load_ms\": %.3f, \"build_ms\": %.3f, \"solve_ms\": %.3f, "
        "\"output_ms\": %.3f}\n",
        method.c_str(), loaded->mesh.file_vertex_count(), loaded->mesh.face_count(),
        sources->size(), (unsigned long long)s.windows_created,
        (unsigned long long)s.windows_filtered_at_creation,
        (unsigned long long)s.windows_filtered_at_pop,
        (unsigned long long)s.windows_filtered_overfilter,
        (unsigned long long)s.children_skipped_one_split,
        (unsigned long long)s.windows_deleted_one_split, (unsigned long long)s.windows_processed,
        (unsigned long long)s.pseudo_sources, (unsigned long long)s.pseudo_sources_full_fan,
        (unsigned long long)s.pseudo_sources_shadow_only, (unsigned long long)s.edge_relaxations, s.max_level,
        (unsigned long long)s.peak_live_windows, (unsigned long long)s.peak_bytes,
        (unsigned long long)loaded->mesh.MemoryBytes(), loaded->load_ms, loaded->build_ms,
        s.solve_ms, MsSince(t_out));
  }
  return kExitOk;
}

namespace {


// Parses a SPEC that must name exactly one point, and checks it against the mesh.
bool OnePoint(const Args& args, const std::string& key, const TriangleMesh& mesh, SurfacePoint* out,
              std::string* error) {
  absl::StatusOr<std::vector<SurfacePoint>> p = ParseSurfacePoints(args.options.at(key));
  if (!p.ok()) {
    *error = absl::StrFormat("--%s: %s", key, p.status().message());
    return false;
  }
  if (p->size() != 1) {
    *error = absl::StrFormat("--%s: expected one point, got %d", key, p->size());
    return false;
  }
  std::unique_ptr<SurfaceLocator> locator;
  if (!ResolvePoints(mesh, key, &*p, &locator, error)) return false;
  *out = p->front();
  return true;
}

}  // namespace

int RunPath(const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"from", "to", "method", "stats", "lambda", "lambda-scale", "max-distance",
                         "max-windows"},
                  &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("from") || !args.options.count("to")) {
    return Fail(kExitUsage, "usage: geodex path MESH --from SPEC --to SPEC [--method astar|full]");
  }
  PathQueryOptions options;
  const std::string method = args.options.count("method") ? args.options.at("method") : "astar";
  if (method == "astar") {
    options.use_heuristic = true;
  } else if (method == "full") {
    options.full_field = true;
  } else {
    return Fail(kExitUsage, "--method must be astar or full");
  }
  if (!GetSolverFlags(args, &options.solver, &error)) return Fail(kExitUsage, error);
  absl::StatusOr<LoadedMesh> loaded = LoadMesh(args.positional[0], MeshBuildOptions{});
  if (!loaded.ok()) return Fail(kExitInput, std::string(loaded.status().message()));
  SurfacePoint from, to;
  if (!OnePoint(args, "from", loaded->mesh, &from, &error) ||
      !OnePoint(args, "to", loaded->mesh, &to, &error)) {
    return Fail(kExitUsage, error);
  }
  absl::StatusOr<PathQueryResult> result = ComputeShortestPath(loaded->mesh, from, to, options);
  if (!result.ok()) {
    const int code = result.status().code() == absl::StatusCode::kInvalidArgument ? kExitUsage
                                                                                   : kExitSolveFailed;
    return Fail(code, std::string(result.status().message()));
  }
  const std::string text = FormatPath(*result);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (args.options.count("stats")) {
    const SolveStats& s = result->stats;
    std::fprintf(stderr,
                 "{\"method\": \"%s\", \"windows_created\": %llu, \"windows_processed\": %llu, "
                 "\"peak_live_windows\": %llu, \"peak_bytes\": %llu, \"path_points\": %zu, "
                 "\"load_ms\": %.3f, \"build_ms\": %.3f, \"solve_ms\": %.3f}\n",
                 method.c_str(), (unsigned long long)s.windows_created,
                 (unsigned long long)s.windows_processed, (unsigned long long)s.peak_live_windows,
                 (unsigned long long)s.peak_bytes, result->path.points.size(), loaded->load_ms,
                 loaded->build_ms, s.solve_ms);
  }
  return kExitOk;
}

int RunMatrix(const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"sources", "targets", "stats", "lambda", "lambda-scale", "max-distance",
                         "max-windows", "k-nearest", "threads"},
                  &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources") ||
      !args.options.count("targets")) {
    return Fail(kExitUsage, "usage: geodex matrix MESH --sources SPEC --targets SPEC");
  }
  MatrixOptions options;
  uint64_t k_nearest = 0, threads = 0;
  if (!GetSolverFlags(args, &options.solver, &error) ||
      !GetUint(args, "k-nearest", &k_nearest, &error) ||
      !GetUint(args, "threads", &threads, &error)) {
    return Fail(kExitUsage, error);
  }
  if (k_nearest > UINT32_MAX) return Fail(kExitUsage, "--k-nearest is too large");
  if (threads > 1024) return Fail(kExitUsage, "--threads must be at most 1024");
  options.k_nearest = static_cast<uint32_t>(k_nearest);
  options.threads = static_cast<unsigned>(threads);
  RowProgress progress;
  options.on_row = [&progress](size_t done, size_t total) { progress.Update(done, total); };
  absl::StatusOr<LoadedMesh> loaded = LoadMesh(args.positional[0], MeshBuildOptions{});
  if (!loaded.ok()) return Fail(kExitInput, std::string(loaded.status().message()));
  std::vector<SurfacePoint> lists[2];
  const char* keys[2] = {"sources", "targets"};
  for (int i = 0; i < 2; ++i) {
    absl::StatusOr<std::vector<SurfacePoint>> p = ParseSurfacePoints(args.options.at(keys[i]));
    if (!p.ok()) return Fail(kExitUsage, absl::StrFormat("--%s: %s", keys[i], p.status().message()));
    std::unique_ptr<SurfaceLocator> locator;
    if (!ResolvePoints(loaded->mesh, keys[i], &*p, &locator, &error)) {
      return Fail(kExitUsage, error);
    }
    lists[i] = *std::move(p);
  }
  absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(loaded->mesh, lists[0], lists[1], options);
  progress.Finish();
  if (!m.ok()) {
    const int code = m.status().code() == absl::StatusCode::kInvalidArgument ? kExitUsage
                                                                              : kExitSolveFailed;
    return Fail(code, std::string(m.status().message()));
  }
  const std::string text = FormatMatrix(*m);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (args.options.count("stats")) {
    std::fprintf(stderr,
                 "{\"rows\": %zu, \"cols\": %zu, \"windows_created\": %llu, \"solve_ms\": %.3f, "
                 "\"threads\": %u}\n",
                 m->rows, m->cols, (unsigned long long)m->stats.windows_created, m->stats.solve_ms,
                 options.threads > 0 ? options.threads : UsableCores());
  }
  return kExitOk;
}

}  // namespace geodex::cli
