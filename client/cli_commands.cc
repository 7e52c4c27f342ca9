#include "cli_commands.h"

#include "cli_backend.h"
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

namespace {

// Parses --`key` (which must be present), then snaps and checks its points on the backend's mesh.
absl::Status Points(Backend& backend, const Args& args, const std::string& key,
                    std::vector<SurfacePoint>* out) {
  absl::StatusOr<std::vector<SurfacePoint>> p = ParseSurfacePoints(args.options.at(key));
  if (!p.ok()) {
    return absl::InvalidArgumentError(absl::StrFormat("--%s: %s", key, p.status().message()));
  }
  if (absl::Status s = backend.Resolve(key, &*p); !s.ok()) return s;
  *out = *std::move(p);
  return absl::OkStatus();
}

// A SPEC that must name exactly one point.
absl::Status OnePoint(Backend& backend, const Args& args, const std::string& key,
                      SurfacePoint* out) {
  std::vector<SurfacePoint> p;
  if (absl::Status s = Points(backend, args, key, &p); !s.ok()) return s;
  if (p.size() != 1) {
    return absl::InvalidArgumentError(
        absl::StrFormat("--%s: expected one point, got %d", key, p.size()));
  }
  *out = p.front();
  return absl::OkStatus();
}

}  // namespace

int OpenMesh(Backend& backend, const std::string& mesh, const MeshBuildOptions& build) {
  absl::Status s = backend.Open(mesh, build);
  if (s.ok()) return kExitOk;
  switch (s.code()) {  // the service failed, not the mesh
    case absl::StatusCode::kUnauthenticated:
    case absl::StatusCode::kUnavailable:
    case absl::StatusCode::kDeadlineExceeded:
    case absl::StatusCode::kResourceExhausted:
    case absl::StatusCode::kCancelled:
      return Fail(kExitSolveFailed, std::string(s.message()));
    default:
      return Fail(kExitInput, std::string(s.message()));
  }
}

namespace {

}  // namespace

int RunInfo(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"format", "strict"}, &error) || !backend.Supports(args, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1) return Fail(kExitUsage, "usage: geodex info MESH [--format json]");
  const std::string format = args.options.count("format") ? args.options.at("format") : "text";
  if (format != "text" && format != "json") {
    return Fail(kExitUsage, "--format must be text or json");
  }
  MeshBuildOptions options;
  options.strict = args.options.count("strict") > 0;
  if (int code = OpenMesh(backend, args.positional[0], options)) return code;
  absl::StatusOr<InfoValues> info = backend.Info();
  if (!info.ok()) return FailQuery(info.status());
  std::fputs(FormatInfo(*info, format == "json").c_str(), stdout);
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

namespace {

// The counters every --stats line carries, after the backend's context.
std::string StatsJson(const Backend& backend, const std::string& leading, const SolveStats& s,
                      const std::string& trailing) {
  return absl::StrFormat(
      "{%s%s\"windows_created\": %llu, \"windows_filtered_at_creation\": %llu, "
      "\"windows_filtered_at_pop\": %llu, \"windows_filtered_overfilter\": %llu, "
      "\"children_skipped_one_split\": %llu, \"windows_deleted_one_split\": %llu, "
      "\"windows_processed\": %llu, \"pseudo_sources\": %llu, \"pseudo_sources_full_fan\": %llu, "
      "\"pseudo_sources_shadow_only\": %llu, \"edge_relaxations\": %llu, \"max_level\": %u, "
      "\"peak_live_windows\": %llu, \"peak_bytes\": %llu, %s\"solve_ms\": %.3f}\n",
      leading, backend.StatsContext(), (unsigned long long)s.windows_created,
      (unsigned long long)s.windows_filtered_at_creation,
      (unsigned long long)s.windows_filtered_at_pop,
      (unsigned long long)s.windows_filtered_overfilter,
      (unsigned long long)s.children_skipped_one_split,
      (unsigned long long)s.windows_deleted_one_split, (unsigned long long)s.windows_processed,
      (unsigned long long)s.pseudo_sources, (unsigned long long)s.pseudo_sources_full_fan,
      (unsigned long long)s.pseudo_sources_shadow_only, (unsigned long long)s.edge_relaxations,
      s.max_level, (unsigned long long)s.peak_live_windows, (unsigned long long)s.peak_bytes,
      trailing, s.solve_ms);
}

}  // namespace

int RunDistances(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"sources", "method", "lambda", "lambda-scale", "max-distance",
                         "max-windows", "stats", "output", "no-filter", "no-one-split", "at"},
                  &error) ||
      !backend.Supports(args, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources")) {
    return Fail(kExitUsage, "usage: geodex distances MESH --sources SPEC [options]");
  }
  FieldOptions options;
  options.method = args.options.count("method") ? args.options.at("method") : "exact";
  if (options.method == "exact") {
    options.solver.method = Method::kExact;
  } else if (options.method == "ich") {
    options.solver.method = Method::kIch;
  } else if (options.method == "dijkstra") {
    options.solver.method = Method::kDijkstra;
  } else {
    return Fail(kExitUsage, "--method must be exact, ich or dijkstra");
  }
  if (!GetSolverFlags(args, &options.solver, &error)) return Fail(kExitUsage, error);
  options.solver.use_filter = !args.options.count("no-filter");
  options.solver.use_one_angle_one_split = !args.options.count("no-one-split");
  absl::StatusOr<std::vector<SurfacePoint>> parsed = ParseSurfacePoints(args.options.at("sources"));
  if (!parsed.ok()) return Fail(kExitUsage, "--sources: " + std::string(parsed.status().message()));
  if (int code = OpenMesh(backend, args.positional[0], MeshBuildOptions{})) return code;
  std::vector<SurfacePoint> sources, at;
  if (absl::Status s = Points(backend, args, "sources", &sources); !s.ok()) return FailQuery(s);
  if (args.options.count("at")) {
    if (absl::Status s = Points(backend, args, "at", &at); !s.ok()) return FailQuery(s);
  }
  std::string text;
  SolveStats stats;
  const auto t_solve = std::chrono::steady_clock::now();
  if (args.options.count("at")) {
    // Surface points: the unfolding estimate and the exact value, one line each.
    absl::StatusOr<std::vector<AtValue>> values = backend.DistancesAt(sources, at, options.solver);
    if (!values.ok()) return FailQuery(values.status());
    for (size_t i = 0; i < at.size(); ++i) {
      text += FormatAtLine(at[i], (*values)[i].estimate, (*values)[i].exact, (*values)[i].source);
    }
  } else {
    absl::StatusOr<DistanceField> field = backend.Field(sources, options);
    if (!field.ok()) return FailQuery(field.status());
    text = FormatDistances(field->distance);
    stats = field->stats;
  }
  if (stats.solve_ms == 0) stats.solve_ms = MsSince(t_solve);
  const auto t_out = std::chrono::steady_clock::now();
  if (int code = WriteOutput(args, text); code != kExitOk) return code;
  if (args.options.count("stats")) {
    const std::string leading =
        absl::StrFormat("\"method\": \"%s\", \"sources\": %d, ", options.method, sources.size());
    const std::string trailing = absl::StrFormat("\"output_ms\": %.3f, ", MsSince(t_out));
    std::fputs(StatsJson(backend, leading, stats, trailing).c_str(), stderr);
  }
  return kExitOk;
}

int RunPath(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"from", "to", "method", "stats", "lambda", "lambda-scale", "max-distance",
                         "max-windows"},
                  &error) ||
      !backend.Supports(args, &error)) {
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
  if (int code = OpenMesh(backend, args.positional[0], MeshBuildOptions{})) return code;
  SurfacePoint from, to;
  if (absl::Status s = OnePoint(backend, args, "from", &from); !s.ok()) return FailQuery(s);
  if (absl::Status s = OnePoint(backend, args, "to", &to); !s.ok()) return FailQuery(s);
  absl::StatusOr<PathQueryResult> result = backend.Path(from, to, options);
  if (!result.ok()) return FailQuery(result.status());
  const std::string text = FormatPath(*result);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (args.options.count("stats")) {
    const std::string leading = absl::StrFormat("\"method\": \"%s\", \"path_points\": %d, ",
                                                method, result->path.points.size());
    std::fputs(StatsJson(backend, leading, result->stats, "").c_str(), stderr);
  }
  return kExitOk;
}

int RunMatrix(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"sources", "targets", "stats", "lambda", "lambda-scale", "max-distance",
                         "max-windows", "k-nearest", "threads"},
                  &error) ||
      !backend.Supports(args, &error)) {
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
  if (int code = OpenMesh(backend, args.positional[0], MeshBuildOptions{})) return code;
  std::vector<SurfacePoint> sources, targets;
  if (absl::Status s = Points(backend, args, "sources", &sources); !s.ok()) return FailQuery(s);
  if (absl::Status s = Points(backend, args, "targets", &targets); !s.ok()) return FailQuery(s);
  absl::StatusOr<DistanceMatrix> m = backend.Matrix(sources, targets, options);
  progress.Finish();
  if (!m.ok()) return FailQuery(m.status());
  const std::string text = FormatMatrix(*m);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (args.options.count("stats")) {
    const std::string leading = absl::StrFormat("\"rows\": %d, \"cols\": %d, \"threads\": %u, ",
                                                m->rows, m->cols,
                                                options.threads > 0 ? options.threads : UsableCores());
    std::fputs(StatsJson(backend, leading, m->stats, "").c_str(), stderr);
  }
  return kExitOk;
}

}  // namespace geodex::cli
