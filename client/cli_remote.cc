#include "cli_remote.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <optional>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli_backend.h"
#include "cli_common.h"
#include "geodex/geodex_client.h"
#include "geodex/surface_point.h"
#include "terrain_convert.h"

namespace geodex::cli {
namespace {

using client::FieldViolation;
using client::FieldViolationOf;
using client::GeodexClient;
using client::MeshRef;

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

// A request point the server refused, named as the flag that gave it, in local mode's words:
// "sources[0].vertex: ..." from geodexd becomes "--sources: point 7: ..." (the field's head is
// looked up in `flags`, request field -> CLI flag). Other errors pass unchanged.
template <typename T>
absl::StatusOr<T> Flagged(
    absl::StatusOr<T> result,
    std::initializer_list<std::pair<absl::string_view, absl::string_view>> flags) {
  if (result.ok()) return result;
  std::optional<FieldViolation> violation = FieldViolationOf(result.status());
  if (!violation.has_value()) return result;
  const absl::string_view head =
      absl::string_view(violation->field).substr(0, violation->field.find_first_of("[."));
  if (head == "options" && violation->field.size() > 8) {  // the solver options: every command's
    return absl::InvalidArgumentError(
        absl::StrCat(FlagOfOption(violation->field.substr(8)), ": ", violation->description));
  }
  for (const auto& [field, flag] : flags) {
    if (head == field) {
      return absl::InvalidArgumentError(absl::StrCat("--", flag, ": ", violation->description));
    }
  }
  return result;
}

// A DEM, or a mesh with --barrier-below, is read here too (its map, its barrier): what the server
// gets is then either the GeoTIFF itself (geodexd reads it the same way and keeps its map) or,
// for other rasters, a barrier file, friction polygons (their outlines cut in) or a mesh file,
// the mesh made here.
bool DerivedHere(const std::string& mesh, const terrain::DemOptions& options) {
  return terrain::IsDemPath(mesh) || std::isfinite(options.barrier_below) ||
         !options.barrier_files.empty() || !options.friction_file.empty();
}
absl::StatusOr<MeshRef> UploadDerived(GeodexClient& client, const std::string& mesh,
                                      const terrain::DemOptions& options, const MeshData& data) {
  // By its content's id, uploaded only if the server lacks it.
  if (terrain::IsGeoTiffPath(mesh) && options.barrier_files.empty() &&
      options.friction_file.empty()) {
    client::DemUploadOptions dem;
    dem.step = options.step;
    if (std::isfinite(options.barrier_below)) dem.barrier_below = options.barrier_below;
    dem.z_tolerance = options.z_tolerance;
    return client.ResolveDem(mesh, data, dem);
  }
  return client.UploadMeshData(std::filesystem::path(mesh).stem().string() + ".off", data);
}

// Queries on a geodexd: MESH resolves to the server's copy (uploaded once, by content hash),
// p:X:Y:Z points are snapped there, so every printed point matches local mode.
class RemoteBackend final : public Backend {
 public:
  explicit RemoteBackend(std::unique_ptr<GeodexClient> client) : client_(std::move(client)) {}

  absl::Status Open(const std::string& mesh, const MeshBuildOptions&,
                    const terrain::DemOptions& dem_options) override {
    mesh_arg_ = mesh;
    std::error_code ec;
    absl::StatusOr<MeshRef> ref;
    const bool barrier =
        std::isfinite(dem_options.barrier_below) || !dem_options.barrier_files.empty();
    const bool here =
        (std::filesystem::exists(mesh, ec) && !std::filesystem::is_directory(mesh, ec)) ||
        mesh.rfind("sample:", 0) == 0;
    if (barrier && !here) return OpenDerivedOnServer(mesh, dem_options);
    if (DerivedHere(mesh, dem_options) && here) {
      absl::StatusOr<MeshData> data = LoadMeshData(mesh, dem_options, &dem_);
      if (!data.ok()) return data.status();
      // The mesh the server gets is this one (the barrier applied): draw and place sites on it.
      if (dem_ == nullptr) data_ = std::make_unique<MeshData>(*data);
      ref = UploadDerived(*client_, mesh, dem_options, *data);
      if (ref.ok() && barrier) {  // the server's count of its parts, as local mode says it
        absl::StatusOr<client::ServerMesh> stored = client_->GetMesh(ref->name);
        if (stored.ok()) WarnIfBarrierSplits(dem_options, stored->summary.report.components);
      }
    } else {
      ref = client_->ResolveMesh(mesh);
    }
    if (!ref.ok()) return ref.status();
    mesh_ = *std::move(ref);
    return absl::OkStatus();
  }

  // A mesh named on the server with a barrier: the server derives it (DeriveMesh). There faces
  // with a corner below --barrier-below go, as on a mesh file (vertices keep their ids, also on a
  // DEM's mesh), and --barrier's GeoJSON is read as on the server's mesh (WGS 84 on a DEM's).
  absl::Status OpenDerivedOnServer(const std::string& mesh, const terrain::DemOptions& options) {
    absl::StatusOr<MeshRef> base = client_->ResolveMesh(mesh);
    if (!base.ok()) return base.status();
    // One DeriveMesh per --barrier file, each cutting the mesh the one before made (the first
    // also takes --barrier-below): every file's polygons end up cut out, as in local mode.
    const size_t files = std::max<size_t>(1, options.barrier_files.size());
    std::string from = base->name;
    absl::StatusOr<client::ServerMesh> derived;
    for (size_t k = 0; k < files; ++k) {
      client::BarrierOptions barrier;
      if (k == 0 && std::isfinite(options.barrier_below)) barrier.below = options.barrier_below;
      const std::string file = k < options.barrier_files.size() ? options.barrier_files[k] : "";
      if (!file.empty()) {
        absl::StatusOr<std::string> text = ReadBarrierText(file);
        if (!text.ok()) return text.status();
        barrier.polygons_geojson = *std::move(text);
        barrier.width = options.barrier_width;
      }
      derived = client_->DeriveMesh(from, barrier);
      if (!derived.ok()) {
        std::optional<FieldViolation> violation = FieldViolationOf(derived.status());
        if (violation.has_value() && violation->field.rfind("barrier", 0) == 0) {
          const bool polygons = violation->field == "barrier.polygons_geojson";
          return absl::InvalidArgumentError(
              absl::StrCat(polygons ? "--barrier " + file : std::string("--barrier-below"), ": ",
                           violation->description));
        }
        return derived.status();
      }
      from = derived->name;
    }
    WarnIfBarrierSplits(options, derived->summary.report.components);
    mesh_.name = derived->name;
    mesh_.id = derived->id();
    return absl::OkStatus();
  }

  bool Supports(const Args& args, std::string* error) const override {
    static const std::pair<const char*, const char*> kLocalOnly[] = {
        {"strict", "geodexd checks a mesh when it is uploaded; run info locally for --strict"},
        {"max-windows", "the window budget of a server is geodexd's --max_windows flag"},
        {"max-steiner-points",
         "the travel engine's memory on a server is geodexd's --max_steiner_points flag"},
        {"threads", "on a server the rows share geodexd's compute pool (--pool-threads)"},
        {"no-filter", "an engine ablation, local only"},
        {"no-one-split", "an engine ablation, local only"},
    };
    for (const auto& [flag, why] : kLocalOnly) {
      if (args.options.count(flag)) {
        *error = absl::StrFormat("--%s: %s", flag, why);
        return false;
      }
    }
    if (args.options.count("method")) {
      const std::string& m = args.options.at("method");
      if (m == "dijkstra") {
        *error =
            "--method dijkstra: local only (geodexd computes exact fields; use --lambda for speed)";
        return false;
      }
      if (m == "full") {
        *error = "--method full: local only (geodexd answers paths with A*, the same exact path)";
        return false;
      }
    }
    return true;
  }

  absl::StatusOr<std::vector<LocatedPoint>> Locate(
      const std::vector<std::array<double, 3>>& xyz) override {
    return client_->Locate(mesh_, xyz);
  }

  absl::Status Check(const std::string&, const std::vector<SurfacePoint>&) override {
    return absl::OkStatus();  // the server checks them with the query, naming the field
  }

  // A DEM read here, or a DEM's mesh named on the server: its grid again from the stored map
  // and geometry (Dem::FromMesh), fetched once, when a command first needs it.
  const terrain::Dem* Terrain() const override {
    if (dem_ != nullptr || !mesh_.file_bytes.empty() || dem_fetched_) return dem_.get();
    dem_fetched_ = true;
    absl::StatusOr<client::ServerMesh> m = client_->GetMesh(mesh_.name);
    if (!m.ok() || !m->has_terrain) return nullptr;
    absl::StatusOr<terrain::DemInfo> info = api::TerrainFromBytes(m->terrain);
    if (!info.ok()) return nullptr;
    absl::StatusOr<MeshData> data = client_->GetMeshGeometry(mesh_);
    if (!data.ok()) return nullptr;
    absl::StatusOr<terrain::Dem> dem = terrain::Dem::FromMesh(*std::move(data), *std::move(info));
    if (dem.ok()) dem_ = std::make_shared<const terrain::Dem>(*std::move(dem));
    return dem_.get();
  }

  absl::StatusOr<const MeshData*> Geometry() override {
    if (dem_ != nullptr) return &dem_->mesh();
    if (data_ == nullptr) {
      // A file or sample given here is read here (its exact coordinates); a mesh named on the
      // server comes from it (GetMeshGeometry).
      absl::StatusOr<MeshData> data =
          mesh_.file_bytes.empty() ? client_->GetMeshGeometry(mesh_) : LoadMeshData(mesh_arg_);
      if (!data.ok()) return data.status();
      data_ = std::make_unique<MeshData>(*std::move(data));
    }
    return data_.get();
  }

  absl::StatusOr<InfoValues> Info() override {
    const auto t0 = std::chrono::steady_clock::now();
    absl::StatusOr<client::ServerMesh> m = client_->GetMesh(mesh_.name);
    if (!m.ok()) return m.status();
    InfoValues v;
    static_cast<MeshSummary&>(v) = m->summary;
    v.load_ms = MsSince(t0);  // remote: the time to describe the mesh
    if (dem_ == nullptr && m->has_terrain) {
      absl::StatusOr<terrain::DemInfo> info = api::TerrainFromBytes(m->terrain);
      if (!info.ok()) return info.status();
      terrain_info_ = *std::move(info);
    }
    v.dem = dem_ ? &dem_->info() : terrain_info_ ? &*terrain_info_ : nullptr;
    return v;
  }

  absl::StatusOr<const DistanceField*> Field(const FieldQuery& query) override {
    absl::StatusOr<DistanceField> f =
        Flagged(client_->Field(mesh_, query, &cached_), {{"sources", "sources"}});
    if (!f.ok()) return f.status();
    if (query.directions && f->direction.size() != f->distance.size()) {
      return absl::UnimplementedError(
          "--directions: the server returned no directions (a geodexd older than this geodex?)");
    }
    field_ = *std::move(f);
    return &field_;
  }

  absl::StatusOr<AtValues> DistancesAt(const PointQuery& query) override {
    // A travel cost has times only (the unfolding estimate is geometry).
    const bool travel = query.options.travel.has_value();
    absl::StatusOr<client::PointDistances> r =
        Flagged(client_->DistancesAtPoints(
                    mesh_, query,
                    travel ? client::PointDistanceMode::kExact : client::PointDistanceMode::kBoth),
                {{"sources", "sources"}, {"points", "at"}});
    if (!r.ok()) return r.status();
    AtValues out;
    for (const PointEstimate& e : r->estimates) out.estimate.push_back(e.distance);
    if (travel) out.estimate.assign(query.points.size(), std::numeric_limits<double>::quiet_NaN());
    out.exact = std::move(r->exact);
    // What the command prints needs one value per point (a geodexd older than this client
    // answers without the directions it does not know).
    const size_t n = query.points.size();
    if (query.directions && out.exact.direction.size() != n) {
      return absl::UnimplementedError(
          "--directions with --at: the server returned no directions (a geodexd older than this "
          "geodex?)");
    }
    if (out.estimate.size() != n || out.exact.distance.size() != n ||
        out.exact.source.size() != n) {
      return absl::InternalError(absl::StrFormat("the server answered %d points for %d asked",
                                                 out.exact.distance.size(), n));
    }
    return out;
  }

  absl::StatusOr<PathQueryResult> Path(const PathQuery& query) override {
    return Flagged(client_->ShortestPath(mesh_, query), {{"from", "from"}, {"to", "to"}});
  }

  absl::StatusOr<DistanceMatrix> Matrix(const MatrixQuery& query) override {
    return Flagged(client_->Matrix(mesh_, query), {{"sources", "sources"}, {"targets", "targets"}});
  }

  absl::StatusOr<Isolines> ComputeIsolines(const IsolineQuery& query) override {
    return Flagged(client_->ComputeIsolines(mesh_, query), {{"sources", "sources"}});
  }
  absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const VoronoiQuery& query) override {
    return Flagged(client_->ComputeVoronoi(mesh_, query), {{"sources", "sites"}});
  }
  absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(const DelaunayQuery& query) override {
    return Flagged(client_->ComputeDelaunay(mesh_, query), {{"sources", "sites"}});
  }

  std::string StatsContext() const override {
    return absl::StrFormat(
        "\"server\": true, \"replica\": \"%s\", \"mesh\": \"%s\", \"uploaded\": %s, "
        "\"reuploads\": %d, \"cached\": %s, ",
        client_->last_replica(), mesh_.name, mesh_.uploaded ? "true" : "false",
        client_->reuploads(), cached_ ? "true" : "false");
  }

 private:
  std::unique_ptr<GeodexClient> client_;
  std::string mesh_arg_;
  mutable MeshRef mesh_;            // (GetMeshGeometry may re-upload, updating it)
  std::unique_ptr<MeshData> data_;  // read from mesh_arg_ on first need
  // When MESH is a DEM: read here, or rebuilt from the server's copy (Terrain()).
  mutable std::shared_ptr<const terrain::Dem> dem_;
  mutable bool dem_fetched_ = false;
  std::optional<terrain::DemInfo> terrain_info_;  // a server DEM's map, for info
  DistanceField field_;  // the last Field answer (Backend::Field hands out a pointer)
  bool cached_ = false;  // the last field came from the server's result cache
};

std::string MeshLine(const client::ServerMesh& m) {
  return absl::StrFormat("%s\t%s\t%d vertices\t%d faces\t%d bytes%s\n", m.name,
                         m.display_name.empty() ? "-" : m.display_name,
                         m.summary.report.file_vertices, m.summary.report.file_faces,
                         m.memory_bytes, m.pinned ? "\tpinned" : "");
}

std::string MeshJson(const client::ServerMesh& m) {
  return absl::StrFormat(
      "{\"name\": \"%s\", \"display_name\": \"%s\", \"vertices\": %d, \"faces\": %d, "
      "\"memory_bytes\": %d, \"upload_bytes\": %d, \"pinned\": %s}",
      m.name, m.display_name, m.summary.report.file_vertices, m.summary.report.file_faces,
      m.memory_bytes, m.upload_bytes, m.pinned ? "true" : "false");
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
    absl::StatusOr<std::vector<client::ServerMesh>> meshes = client.ListMeshes();
    if (!meshes.ok()) return FailQuery(meshes.status());
    std::string out = json ? "[" : "";
    for (size_t i = 0; i < meshes->size(); ++i) {
      out += json ? (i ? ", " : "") + MeshJson((*meshes)[i]) : MeshLine((*meshes)[i]);
    }
    std::fputs((json ? out + "]\n" : out).c_str(), stdout);
    return kExitOk;
  }
  if ((sub == "get" || sub == "delete") && p.size() == 2) {
    absl::StatusOr<MeshRef> mesh = client.ResolveMesh(p[1]);
    if (!mesh.ok()) return FailQuery(mesh.status());
    if (sub == "delete") {
      absl::Status s = client.DeleteMesh(mesh->name);
      if (!s.ok()) return FailQuery(s);
      std::printf("deleted %s\n", mesh->name.c_str());
      return kExitOk;
    }
    absl::StatusOr<client::ServerMesh> m = client.GetMesh(mesh->name);
    if (!m.ok()) return FailQuery(m.status());
    std::fputs((json ? MeshJson(*m) + "\n" : MeshLine(*m)).c_str(), stdout);
    return kExitOk;
  }
  if (sub == "upload" && p.size() == 2) {
    absl::StatusOr<terrain::DemOptions> dem = MeshReadOptions(args, p[1]);
    if (!dem.ok()) return Fail(kExitUsage, std::string(dem.status().message()));
    absl::StatusOr<MeshData> data = LoadMeshData(p[1], *dem);
    if (!data.ok()) return Fail(kExitInput, std::string(data.status().message()));
    absl::StatusOr<MeshRef> ref =  // uploads only if missing
        DerivedHere(p[1], *dem) ? UploadDerived(client, p[1], *dem, *data)
                                : client.ResolveMesh(p[1]);
    if (!ref.ok()) return FailQuery(ref.status());
    absl::StatusOr<client::ServerMesh> m =
        args.options.count("name") ? client.Upload(ref->file_name, ref->file_bytes,
                                                   args.options.at("name"), ref->id, ref->dem)
                                   : client.GetMesh(ref->name);
    if (!m.ok()) return FailQuery(m.status());
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

std::unique_ptr<Backend> MakeRemoteBackend(const std::string& target) {
  return std::make_unique<RemoteBackend>(Connect(target));
}

int RunServerCommand(const std::string& target, const std::string& command, const Args& args) {
  std::unique_ptr<GeodexClient> client = Connect(target);
  if (command == "mesh") return RemoteMesh(*client, args);
  if (command == "health") return RemoteHealth(*client, args);
  return Fail(kExitUsage, absl::StrFormat("unknown command '%s' (see geodex --help)", command));
}

}  // namespace geodex::cli
