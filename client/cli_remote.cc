#include "cli_remote.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli_common.h"
#include "geodex_client.h"
#include "geodex/surface_point.h"

namespace geodex::cli {
namespace {

using client::GeodexClient;
using client::MeshRef;

// Exit code of a failed call: bad arguments 2, unknown or unreadable mesh 3, anything else 1.
int Code(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kOutOfRange:
      return kExitUsage;
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kDataLoss:
      return kExitInput;
    default:
      return kExitSolveFailed;
  }
}

int FailStatus(const absl::Status& status) {
  return Fail(Code(status), std::string(status.message()));
}

class RemoteGeometryImpl final : public RemoteGeometry {
 public:
  explicit RemoteGeometryImpl(std::unique_ptr<GeodexClient> client) : client_(std::move(client)) {}
  absl::Status Prepare(const std::string& mesh, std::vector<SurfacePoint>* points) override;
  absl::StatusOr<DistanceField> ComputeField(const std::vector<SurfacePoint>& sources) override {
    return client_->Field(mesh_, sources, v1::SolverOptions());
  }
  absl::StatusOr<PathQueryResult> ComputePath(const SurfacePoint& from,
                                              const SurfacePoint& to) override {
    return client_->ShortestPath(mesh_, from, to, v1::SolverOptions());
  }
  absl::StatusOr<Isolines> ComputeIsolines(const std::vector<SurfacePoint>& sources,
                                           const IsolineOptions& levels) override {
    return client_->ComputeIsolines(mesh_, sources, levels, v1::SolverOptions());
  }
  absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const std::vector<SurfacePoint>& sites) override {
    return client_->ComputeVoronoi(mesh_, sites, v1::SolverOptions());
  }
  absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(
      const std::vector<SurfacePoint>& sites) override {
    return client_->ComputeDelaunay(mesh_, sites, v1::SolverOptions());
  }

 private:
  std::unique_ptr<GeodexClient> client_;
  MeshRef mesh_;
};

// A progress bar on stderr for uploads, only when stderr is a terminal.
void UploadProgress(uint64_t done, uint64_t total) {
  if (!::isatty(2) || total == 0) return;
  const int width = 30, filled = static_cast<int>(width * done / total);
  std::fprintf(stderr, "\rupload [%s%s] %3d%%", std::string(filled, '#').c_str(),
               std::string(width - filled, ' ').c_str(), static_cast<int>(100 * done / total));
  if (done == total) std::fputs("\n", stderr);
}

RemoteOptions g_remote;

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::unique_ptr<GeodexClient> Connect(const std::string& target) {
  client::ClientOptions options;
  options.target = target;
  options.upload_progress = UploadProgress;
  options.tls = g_remote.tls || !g_remote.ca_file.empty();
  if (!g_remote.ca_file.empty()) options.ca_pem = ReadText(g_remote.ca_file);
  if (!g_remote.token_file.empty()) {
    options.token = std::string(absl::StripAsciiWhitespace(ReadText(g_remote.token_file)));
    options.token = options.token.substr(0, options.token.find('\n'));
  } else if (const char* env = std::getenv("GEODEX_TOKEN")) {
    options.token = env;
  }
  return std::make_unique<GeodexClient>(options);
}

// --lambda, --lambda-scale, --max-distance as the API's SolverOptions.
bool SolverOptions(const Args& args, v1::SolverOptions* out, std::string* error) {
  double lambda = 0, max_distance = INFINITY;
  if (!GetDouble(args, "lambda", &lambda, error) ||
      !GetDouble(args, "max-distance", &max_distance, error)) {
    return false;
  }
  if (!(lambda >= 0 && lambda <= 1)) {
    *error = absl::StrFormat("--lambda must be in [0, 1], got %g", lambda);
    return false;
  }
  if (!(max_distance > 0)) {
    *error = "--max-distance must be positive";
    return false;
  }
  out->set_lambda(lambda);
  if (std::isfinite(max_distance)) out->set_max_distance(max_distance);
  if (args.options.count("lambda-scale")) {
    const std::string& s = args.options.at("lambda-scale");
    if (s == "max") {
      out->set_lambda_scale(v1::LAMBDA_SCALE_MAX_EDGE);
    } else if (s == "mean") {
      out->set_lambda_scale(v1::LAMBDA_SCALE_MEAN_EDGE);
    } else {
      *error = "--lambda-scale must be max or mean";
      return false;
    }
  }
  return true;
}

bool Points(const Args& args, const std::string& key, std::vector<SurfacePoint>* out,
            std::string* error) {
  absl::StatusOr<std::vector<SurfacePoint>> p = ParseSurfacePoints(args.options.at(key));
  if (!p.ok()) {
    *error = absl::StrFormat("--%s: %s", key, p.status().message());
    return false;
  }
  *out = *std::move(p);
  return true;
}

// Positions (p:X:Y:Z) located on the server, so that printed points match local mode.
absl::Status LocatePositions(GeodexClient& client, MeshRef& mesh, std::vector<SurfacePoint>* points) {
  std::vector<std::array<double, 3>> xyz;
  for (const SurfacePoint& p : *points) {
    if (p.kind == SurfacePoint::Kind::kPosition) xyz.push_back(p.position);
  }
  if (xyz.empty()) return absl::OkStatus();
  absl::StatusOr<std::vector<SurfacePoint>> located = client.Locate(mesh, xyz);
  if (!located.ok()) return located.status();
  size_t k = 0;
  for (SurfacePoint& p : *points) {
    if (p.kind == SurfacePoint::Kind::kPosition) p = (*located)[k++];
  }
  return absl::OkStatus();
}

absl::Status RemoteGeometryImpl::Prepare(const std::string& mesh, std::vector<SurfacePoint>* points) {
  absl::StatusOr<MeshRef> ref = client_->ResolveMesh(mesh);
  if (!ref.ok()) return ref.status();
  mesh_ = *std::move(ref);
  return LocatePositions(*client_, mesh_, points);
}

int RemoteInfo(GeodexClient& client, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"format"}, &error)) return Fail(kExitUsage, error);
  if (args.positional.size() != 1) return Fail(kExitUsage, "usage: geodex info MESH [--format json]");
  const std::string format = args.options.count("format") ? args.options.at("format") : "text";
  if (format != "text" && format != "json") return Fail(kExitUsage, "--format must be text or json");
  const auto t0 = std::chrono::steady_clock::now();
  absl::StatusOr<MeshRef> mesh = client.ResolveMesh(args.positional[0]);
  if (!mesh.ok()) return FailStatus(mesh.status());
  absl::StatusOr<v1::Mesh> m = client.GetMesh(mesh->name);
  if (!m.ok()) return FailStatus(m.status());
  const v1::MeshInfo& i = m->info();
  InfoValues v;
  v.report.file_vertices = m->vertex_count();
  v.report.file_faces = m->face_count();
  v.report.boundary_edges = m->boundary_edges();
  v.report.boundary_loops = i.boundary_loops();
  v.report.components = m->components();
  v.report.vertex_connected_components = i.vertex_connected_components();
  v.report.isolated_vertices = i.isolated_vertices();
  v.report.non_manifold_edges = m->non_manifold_edges();
  v.report.non_manifold_vertices = i.non_manifold_vertices();
  v.report.degenerate_faces = m->degenerate_faces();
  v.report.flipped_faces = i.flipped_faces();
  v.report.orientation_cuts = i.orientation_cuts();
  v.report.saddle_vertices = i.saddle_vertices();
  v.report.boundary_vertices = i.boundary_vertices();
  v.internal_vertices = i.internal_vertices();
  v.mean_edge_length = i.mean_edge_length();
  v.max_edge_length = i.max_edge_length();
  v.bbox_min = {i.bbox_min().x(), i.bbox_min().y(), i.bbox_min().z()};
  v.bbox_max = {i.bbox_max().x(), i.bbox_max().y(), i.bbox_max().z()};
  v.bytes = i.mesh_bytes();
  v.load_ms = MsSince(t0);  // remote: the time to resolve and describe the mesh
  std::fputs(FormatInfo(v, format == "json").c_str(), stdout);
  return kExitOk;
}

int RemoteDistances(GeodexClient& client, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"sources", "method", "lambda", "lambda-scale", "max-distance", "stats",
                         "output", "at"},
                  &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources")) {
    return Fail(kExitUsage, "usage: geodex distances MESH --sources SPEC [options]");
  }
  if (args.options.count("method") && args.options.at("method") != "ich") {
    return Fail(kExitUsage, "--method: the server computes exact ICH fields only (use lambda)");
  }
  v1::SolverOptions options;
  std::vector<SurfacePoint> sources, at;
  if (!SolverOptions(args, &options, &error) || !Points(args, "sources", &sources, &error) ||
      (args.options.count("at") && !Points(args, "at", &at, &error))) {
    return Fail(kExitUsage, error);
  }
  absl::StatusOr<MeshRef> mesh = client.ResolveMesh(args.positional[0]);
  if (!mesh.ok()) return FailStatus(mesh.status());
  std::string text;
  SolveStats stats;
  bool cached = false;
  if (args.options.count("at")) {
    if (absl::Status s = LocatePositions(client, *mesh, &at); !s.ok()) return FailStatus(s);
    absl::StatusOr<v1::EstimateDistancesResponse> r = client.PointDistances(
        *mesh, sources, at, v1::POINT_DISTANCE_MODE_BOTH, options);
    if (!r.ok()) return FailStatus(r.status());
    for (size_t k = 0; k < at.size(); ++k) {
      const int i = static_cast<int>(k);
      text += FormatAtLine(at[k], r->estimates(i), r->exact(i), r->exact_labels(i));
    }
  } else {
    absl::StatusOr<DistanceField> field = client.Field(*mesh, sources, options, &cached);
    if (!field.ok()) return FailStatus(field.status());
    text = FormatDistances(field->distance);
    stats = field->stats;
  }
  if (int code = WriteOutput(args, text); code != kExitOk) return code;
  if (args.options.count("stats")) {
    std::fprintf(stderr,
                 "{\"server\": true, \"replica\": \"%s\", \"mesh\": \"%s\", \"uploaded\": %s, "
                 "\"reuploads\": %d, \"cached\": %s, "
                 "\"windows_created\": %llu, \"windows_processed\": %llu, \"max_level\": %u, "
                 "\"peak_live_windows\": %llu, \"peak_bytes\": %llu, \"solve_ms\": %.3f}\n",
                 client.last_replica().c_str(), mesh->name.c_str(),
                 mesh->uploaded ? "true" : "false", client.reuploads(), cached ? "true" : "false",
                 (unsigned long long)stats.windows_created,
                 (unsigned long long)stats.windows_processed, stats.max_level,
                 (unsigned long long)stats.peak_live_windows, (unsigned long long)stats.peak_bytes,
                 stats.solve_ms);
  }
  return kExitOk;
}

int RemotePath(GeodexClient& client, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"from", "to", "method", "stats", "lambda"}, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("from") || !args.options.count("to")) {
    return Fail(kExitUsage, "usage: geodex path MESH --from SPEC --to SPEC [--method astar|full]");
  }
  if (args.options.count("method") && args.options.at("method") != "astar") {
    return Fail(kExitUsage, "--method: the server answers paths with A* (exact) only");
  }
  v1::SolverOptions options;
  std::vector<SurfacePoint> from, to;
  if (!SolverOptions(args, &options, &error) || !Points(args, "from", &from, &error) ||
      !Points(args, "to", &to, &error)) {
    return Fail(kExitUsage, error);
  }
  if (from.size() != 1 || to.size() != 1) {
    return Fail(kExitUsage, "--from and --to: expected one point each");
  }
  absl::StatusOr<MeshRef> mesh = client.ResolveMesh(args.positional[0]);
  if (!mesh.ok()) return FailStatus(mesh.status());
  absl::StatusOr<PathQueryResult> result = client.ShortestPath(*mesh, from[0], to[0], options);
  if (!result.ok()) {
    // FAILED_PRECONDITION (ErrorInfo UNREACHABLE): the target is not reachable, as locally.
    return Fail(result.status().code() == absl::StatusCode::kFailedPrecondition
                    ? kExitSolveFailed
                    : Code(result.status()),
                std::string(result.status().message()));
  }
  const std::string text = FormatPath(*result);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (args.options.count("stats")) {
    std::fprintf(stderr,
                 "{\"server\": true, \"replica\": \"%s\", \"windows_created\": %llu, "
                 "\"windows_processed\": %llu, \"path_points\": %zu, \"solve_ms\": %.3f}\n",
                 client.last_replica().c_str(),
                 (unsigned long long)result->stats.windows_created,
                 (unsigned long long)result->stats.windows_processed, result->path.points.size(),
                 result->stats.solve_ms);
  }
  return kExitOk;
}

int RemoteMatrix(GeodexClient& client, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"sources", "targets", "stats", "lambda", "lambda-scale", "max-distance",
                         "k-nearest"},
                  &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources") ||
      !args.options.count("targets")) {
    return Fail(kExitUsage, "usage: geodex matrix MESH --sources SPEC --targets SPEC");
  }
  v1::SolverOptions options;
  uint64_t k_nearest = 0;
  if (!SolverOptions(args, &options, &error) || !GetUint(args, "k-nearest", &k_nearest, &error)) {
    return Fail(kExitUsage, error);
  }
  if (k_nearest > UINT32_MAX) return Fail(kExitUsage, "--k-nearest is too large");
  std::vector<SurfacePoint> sources, targets;
  if (!Points(args, "sources", &sources, &error) || !Points(args, "targets", &targets, &error)) {
    return Fail(kExitUsage, error);
  }
  absl::StatusOr<MeshRef> mesh = client.ResolveMesh(args.positional[0]);
  if (!mesh.ok()) return FailStatus(mesh.status());
  RowProgress progress;
  absl::StatusOr<DistanceMatrix> m =
      client.Matrix(*mesh, sources, targets, options, static_cast<uint32_t>(k_nearest),
                    [&progress](size_t done, size_t total) { progress.Update(done, total); });
  progress.Finish();
  if (!m.ok()) return FailStatus(m.status());
  const std::string text = FormatMatrix(*m);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (args.options.count("stats")) {
    std::fprintf(stderr, "{\"rows\": %zu, \"cols\": %zu, \"windows_created\": %llu, \"solve_ms\": %.3f}\n",
                 m->rows, m->cols, (unsigned long long)m->stats.windows_created, m->stats.solve_ms);
  }
  return kExitOk;
}

std::string MeshLine(const v1::Mesh& m) {
  return absl::StrFormat("%s\t%s\t%d vertices\t%d faces\t%d bytes%s\n", m.name(),
                         m.display_name().empty() ? "-" : m.display_name(), m.vertex_count(),
                         m.face_count(), m.memory_bytes(), m.pinned() ? "\tpinned" : "");
}

std::string MeshJson(const v1::Mesh& m) {
  return absl::StrFormat(
      "{\"name\": \"%s\", \"display_name\": \"%s\", \"vertices\": %d, \"faces\": %d, "
      "\"memory_bytes\": %d, \"upload_bytes\": %d, \"pinned\": %s}",
      m.name(), m.display_name(), m.vertex_count(), m.face_count(), m.memory_bytes(),
      m.upload_bytes(), m.pinned() ? "true" : "false");
}

// geodex mesh upload FILE [--name NAME] | list | get MESH | delete MESH
int RemoteMesh(GeodexClient& client, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"name", "format"}, &error)) return Fail(kExitUsage, error);
  const std::string format = args.options.count("format") ? args.options.at("format") : "text";
  const bool json = format == "json";
  if (format != "text" && !json) return Fail(kExitUsage, "--format must be text or json");
  const std::vector<std::string>& p = args.positional;
  const std::string sub = p.empty() ? "" : p[0];
  if (sub == "list" && p.size() == 1) {
    absl::StatusOr<std::vector<v1::Mesh>> meshes = client.ListMeshes();
    if (!meshes.ok()) return FailStatus(meshes.status());
    std::string out = json ? "[" : "";
    for (size_t i = 0; i < meshes->size(); ++i) {
      out += json ? (i ? ", " : "") + MeshJson((*meshes)[i]) : MeshLine((*meshes)[i]);
    }
    std::fputs((json ? out + "]\n" : out).c_str(), stdout);
    return kExitOk;
  }
  if ((sub == "get" || sub == "delete") && p.size() == 2) {
    absl::StatusOr<MeshRef> mesh = client.ResolveMesh(p[1]);
    if (!mesh.ok()) return FailStatus(mesh.status());
    if (sub == "delete") {
      absl::Status s = client.DeleteMesh(mesh->name);
      if (!s.ok()) return FailStatus(s);
      std::printf("deleted %s\n", mesh->name.c_str());
      return kExitOk;
    }
    absl::StatusOr<v1::Mesh> m = client.GetMesh(mesh->name);
    if (!m.ok()) return FailStatus(m.status());
    std::fputs((json ? MeshJson(*m) + "\n" : MeshLine(*m)).c_str(), stdout);
    return kExitOk;
  }
  if (sub == "upload" && p.size() == 2) {
    absl::StatusOr<MeshData> data = LoadMeshData(p[1]);
    if (!data.ok()) return Fail(kExitInput, std::string(data.status().message()));
    absl::StatusOr<MeshRef> ref = client.ResolveMesh(p[1]);  // uploads only if missing
    if (!ref.ok()) return FailStatus(ref.status());
    absl::StatusOr<v1::Mesh> m =
        args.options.count("name")
            ? client.Upload(ref->file_name, ref->file_bytes, args.options.at("name"), ref->id)
            : client.GetMesh(ref->name);
    if (!m.ok()) return FailStatus(m.status());
    std::fputs((json ? MeshJson(*m) + "\n" : MeshLine(*m)).c_str(), stdout);
    return kExitOk;
  }
  return Fail(kExitUsage,
              "usage: geodex --server HOST:PORT mesh upload FILE [--name NAME] | list | get MESH | "
              "delete MESH");
}

int RemoteHealth(GeodexClient& client, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"service"}, &error)) return Fail(kExitUsage, error);
  const std::string service = args.options.count("service") ? args.options.at("service") : "";
  absl::StatusOr<bool> serving = client.Health(service);
  if (!serving.ok()) return Fail(kExitSolveFailed, std::string(serving.status().message()));
  std::puts(*serving ? "SERVING" : "NOT_SERVING");
  return *serving ? kExitOk : kExitSolveFailed;
}

}  // namespace

bool RemoteAvailable() { return true; }

void SetRemoteOptions(const RemoteOptions& options) { g_remote = options; }

std::unique_ptr<RemoteGeometry> ConnectRemoteGeometry(const std::string& target) {
  return std::make_unique<RemoteGeometryImpl>(Connect(target));
}

int FailRemote(const absl::Status& status) { return FailStatus(status); }

int RunRemote(const std::string& target, const std::string& command, const Args& args) {
  std::unique_ptr<GeodexClient> client = Connect(target);
  if (command == "info") return RemoteInfo(*client, args);
  if (command == "distances") return RemoteDistances(*client, args);
  if (command == "path") return RemotePath(*client, args);
  if (command == "matrix") return RemoteMatrix(*client, args);
  if (command == "mesh") return RemoteMesh(*client, args);
  if (command == "health") return RemoteHealth(*client, args);
  return Fail(kExitUsage, absl::StrFormat("unknown command '%s' (see geodex --help)", command));
}

}  // namespace geodex::cli
