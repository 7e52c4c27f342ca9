#include "geodex/geodex_client.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>
#include <utility>

#include "absl/strings/cord.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "api_convert.h"
#include "geodex/mesh_id.h"
#include "geodex/mesh_io.h"
#include "geodex/samples.h"
#include "geodex/v1/geodex.grpc.pb.h"
#include "geometry_convert.h"
#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/byte_buffer.h"

namespace geodex::client {

// The generated stub, kept out of the public header.
struct GeodexClient::Stub {
  std::unique_ptr<v1::Geodex::Stub> rpc;
};

namespace {

// ClientOptions::max_snap on a request that takes points (unset when +inf).
template <typename Request>
void SetMaxSnap(double max_snap, Request* request) {
  if (std::isfinite(max_snap)) request->set_max_snap(max_snap);
}

// The client's own types on the wire (the rest is proto/convert's).
ServerMesh ServerMeshFromProto(const v1::Mesh& m) {
  ServerMesh out;
  out.name = m.name();
  out.display_name = m.display_name();
  out.aliases.assign(m.aliases().begin(), m.aliases().end());
  out.summary = api::MeshSummaryFromProto(m);
  out.upload_bytes = m.upload_bytes();
  out.memory_bytes = m.memory_bytes();
  out.pinned = m.pinned();
  out.create_time_seconds = m.create_time().seconds();
  out.has_terrain = m.has_terrain();
  if (out.has_terrain) {
    out.terrain = m.terrain().SerializeAsString();
    const v1::Terrain& t = m.terrain();
    ServerTerrain& map = out.map.emplace();
    map.driver = t.driver();
    map.raster_width = t.raster_width();
    map.raster_height = t.raster_height();
    map.step = t.step();
    map.grid_width = t.grid_width();
    map.grid_height = t.grid_height();
    map.nodata_cells = t.nodata_cells();
    map.barrier_cells = t.barrier_cells();
    map.barrier_faces = t.barrier_faces();
    map.crs_name = t.crs_name();
    map.crs_wkt = t.crs_wkt();
    map.reprojected = t.reprojected();
    map.mesh_crs_name = t.mesh_crs_name();
    map.mesh_crs_wkt = t.mesh_crs_wkt();
    map.horizontal_scale = t.horizontal_scale();
    map.vertical_unit = t.vertical_unit();
    map.vertical_scale = t.vertical_scale();
    for (int i = 0; i < t.geotransform_size() && i < 6; ++i)
      map.geotransform[i] = t.geotransform(i);
    map.z_tolerance = t.z_tolerance();
    map.max_vertical_deviation = t.max_vertical_deviation();
    map.rms_vertical_deviation = t.rms_vertical_deviation();
  }
  return out;
}

v1::DemOptions DemOptionsToProto(const DemUploadOptions& options) {
  v1::DemOptions out;
  out.set_step(options.step);
  if (options.barrier_below.has_value()) out.set_barrier_below(*options.barrier_below);
  out.set_z_tolerance(options.z_tolerance);
  return out;
}

v1::Barrier BarrierToProto(const BarrierOptions& options) {
  v1::Barrier out;
  if (options.below.has_value()) out.set_below(*options.below);
  out.set_polygons_geojson(options.polygons_geojson);
  out.set_width(options.width);
  return out;
}

v1::PointDistanceMode ModeToProto(PointDistanceMode mode) {
  switch (mode) {
    case PointDistanceMode::kExact:
      return v1::POINT_DISTANCE_MODE_EXACT;
    case PointDistanceMode::kBoth:
      return v1::POINT_DISTANCE_MODE_BOTH;
    case PointDistanceMode::kEstimate:
      break;
  }
  return v1::POINT_DISTANCE_MODE_ESTIMATE;
}

constexpr absl::string_view kFieldPayload = "geodex.client/field";
constexpr absl::string_view kDescriptionPayload = "geodex.client/field-description";

// The code and message, and a BadRequest's first field violation as payloads (FieldViolationOf).
absl::Status ToAbsl(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  absl::Status out(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
  google::rpc::Status details;
  if (!status.error_details().empty() && details.ParseFromString(status.error_details())) {
    for (const google::protobuf::Any& any : details.details()) {
      google::rpc::BadRequest bad_request;
      if (any.UnpackTo(&bad_request) && bad_request.field_violations_size() > 0) {
        out.SetPayload(kFieldPayload, absl::Cord(bad_request.field_violations(0).field()));
        out.SetPayload(kDescriptionPayload,
                       absl::Cord(bad_request.field_violations(0).description()));
        break;
      }
    }
  }
  return out;
}

// The mesh id in "meshes/{id}", or "" when the name holds an alias.
std::string IdOfName(const std::string& name) {
  return name.size() == 71 && IsMeshId(name.substr(7)) ? name.substr(7) : "";
}

}  // namespace

std::optional<FieldViolation> FieldViolationOf(const absl::Status& status) {
  auto field = status.GetPayload(kFieldPayload);  // absl::optional in Debian's Abseil
  if (!field.has_value()) return std::nullopt;
  auto description = status.GetPayload(kDescriptionPayload);
  return FieldViolation{std::string(*field), description ? std::string(*description) : ""};
}

std::string MeshToOffText(const MeshData& mesh) {
  std::string out = absl::StrFormat("OFF\n%d %d 0\n", mesh.vertex_count(), mesh.face_count());
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    absl::StrAppendFormat(&out, "%.17g %.17g %.17g\n", mesh.positions[3 * v],
                          mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]);
  }
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    absl::StrAppendFormat(&out, "3 %d %d %d\n", mesh.faces[3 * f], mesh.faces[3 * f + 1],
                          mesh.faces[3 * f + 2]);
  }
  return out;
}

void Cancellation::Cancel() {
  std::lock_guard<std::mutex> lock(mu_);
  cancelled_ = true;
  for (grpc::ClientContext* context : in_flight_) context->TryCancel();
}

bool Cancellation::cancelled() const {
  std::lock_guard<std::mutex> lock(mu_);
  return cancelled_;
}

bool Cancellation::Register(grpc::ClientContext* context) {
  std::lock_guard<std::mutex> lock(mu_);
  if (cancelled_) return false;
  in_flight_.push_back(context);
  return true;
}

void Cancellation::Unregister(grpc::ClientContext* context) {
  std::lock_guard<std::mutex> lock(mu_);
  in_flight_.erase(std::remove(in_flight_.begin(), in_flight_.end(), context), in_flight_.end());
}

GeodexClient::GeodexClient(ClientOptions options)
    : options_(std::move(options)), state_(std::make_unique<State>()) {
  state_->deadline_seconds = options_.deadline_seconds;
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(4 << 20);  // gRPC's default, kept on purpose: the API streams
  // Reconnect soon after a server comes back (gRPC waits 1 s, then 1.6 s, 2.6 s, ... by default).
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
  args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 100);
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 1000);
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (options_.tls) {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = options_.ca_pem;
    credentials = grpc::SslCredentials(ssl);
  }
  channel_ = grpc::CreateCustomChannel(options_.target, credentials, args);
  stub_ = std::make_unique<Stub>(Stub{v1::Geodex::NewStub(channel_)});
}

GeodexClient::~GeodexClient() = default;
GeodexClient::GeodexClient(GeodexClient&&) noexcept = default;
GeodexClient& GeodexClient::operator=(GeodexClient&&) noexcept = default;

namespace {
// RESOURCE_EXHAUSTED because every worker was busy and the queue full (ErrorInfo reason QUEUE_FULL,
// see server/status_convert.h), as opposed to a request over a limit.
// The ErrorInfo reason geodexd attached to a failed call ("QUEUE_FULL", "MESH_NOT_FOUND", ...;
// see server/status_convert.h), or "".
std::string ErrorReason(const grpc::Status& status) {
  google::rpc::Status details;
  if (!details.ParseFromString(status.error_details())) return "";
  for (const google::protobuf::Any& any : details.details()) {
    google::rpc::ErrorInfo info;
    if (any.UnpackTo(&info)) return info.reason();
  }
  return "";
}

bool IsQueueFull(const grpc::Status& status) {
  return status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED &&
         ErrorReason(status) == "QUEUE_FULL";
}
}  // namespace

namespace {
grpc::Status CancelledByCaller() {
  return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled by the caller");
}

// Sleeps `seconds`, or less when `cancel` is cancelled meanwhile.
void SleepUnlessCancelled(double seconds, const Cancellation* cancel) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until && !(cancel && cancel->cancelled())) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}
}  // namespace

grpc::Status GeodexClient::Call(const std::string& mesh_id,
                                const std::function<grpc::Status(grpc::ClientContext*)>& call,
                                const CallOptions& options) {
  double backoff = options_.initial_backoff_seconds;
  const double deadline_seconds = options.deadline_seconds.value_or(state_->deadline_seconds);
  Cancellation* cancel = options.cancel.get();
  grpc::Status status;
  // UNAVAILABLE (a restart, a drain) is retried while the server may come back: each retry waits
  // for the channel to connect, up to reconnect_wait_seconds from the first one; a full queue is
  // retried max_attempts times.
  using Clock = std::chrono::system_clock;
  constexpr Clock::time_point kNotWaiting = Clock::time_point::max();
  Clock::time_point reconnect_until = kNotWaiting;
  for (int attempt = 0;; ++attempt) {
    if (attempt > 0) {
      ++state_->retries;
      SleepUnlessCancelled(std::min(backoff, 1.0), cancel);
      backoff *= 2;
      // Waits for the channel in short steps, so that a cancel is seen.
      bool connected = reconnect_until == kNotWaiting;
      while (!connected && !(cancel && cancel->cancelled()) && Clock::now() < reconnect_until) {
        connected = channel_->WaitForConnected(
            std::min(reconnect_until, Clock::now() + std::chrono::milliseconds(100)));
      }
      if (cancel && cancel->cancelled()) return CancelledByCaller();
      if (!connected) break;
    }
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() +
                         std::chrono::microseconds(static_cast<int64_t>(deadline_seconds * 1e6)));
    if (options_.wait_for_ready) context.set_wait_for_ready(true);
    if (!mesh_id.empty()) context.AddMetadata("x-mesh-id", mesh_id);
    if (!options_.token.empty()) context.AddMetadata("authorization", "Bearer " + options_.token);
    if (cancel && !cancel->Register(&context)) return CancelledByCaller();
    ++state_->calls;
    status = call(&context);
    if (cancel) cancel->Unregister(&context);
    if (cancel && cancel->cancelled()) return CancelledByCaller();
    {
      const auto& metadata = context.GetServerInitialMetadata();
      auto it = metadata.find("x-geodex-replica");
      std::lock_guard<std::mutex> lock(state_->mu);
      state_->last_replica =
          it == metadata.end() ? "" : std::string(it->second.data(), it->second.size());
    }
    if (status.error_code() == grpc::StatusCode::UNAVAILABLE) {
      if (reconnect_until == kNotWaiting) {
        reconnect_until =
            Clock::now() + std::chrono::microseconds(static_cast<int64_t>(
                               std::min(options_.reconnect_wait_seconds, deadline_seconds) * 1e6));
      }
      if (Clock::now() < reconnect_until) continue;
      break;
    }
    reconnect_until = kNotWaiting;
    if (!(options_.retry_queue_full && IsQueueFull(status)) ||
        attempt + 1 >= std::max(1, options_.max_attempts)) {
      break;
    }
  }
  return status;
}

grpc::Status GeodexClient::MeshCall(MeshRef& mesh,
                                    const std::function<grpc::Status(grpc::ClientContext*)>& call,
                                    const CallOptions& options) {
  grpc::Status status = Call(mesh.id, call, options);
  if (status.error_code() == grpc::StatusCode::NOT_FOUND && !mesh.file_bytes.empty() &&
      ErrorReason(status) == "MESH_NOT_FOUND") {
    // The server lost (or never had) the mesh: upload it again and retry once.
    absl::StatusOr<ServerMesh> uploaded =
        Upload(mesh.file_name, mesh.file_bytes, "", mesh.id, mesh.dem);
    if (!uploaded.ok()) {
      return grpc::Status(static_cast<grpc::StatusCode>(uploaded.status().code()),
                          std::string(uploaded.status().message()));
    }
    ++state_->reuploads;
    status = Call(mesh.id, call, options);
  }
  return status;
}

absl::StatusOr<bool> GeodexClient::Health(const std::string& service) {
  grpc::GenericStub generic(channel_);
  std::string request;
  if (!service.empty()) {
    request.push_back(0x0a);
    request.push_back(static_cast<char>(service.size()));
    request += service;
  }
  std::string reply;
  grpc::Status status = Call("", [&](grpc::ClientContext* context) {
    grpc::Slice slice(request);
    grpc::ByteBuffer in(&slice, 1), out;
    std::promise<grpc::Status> done;
    generic.UnaryCall(context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &in, &out,
                      [&](grpc::Status s) { done.set_value(s); });
    grpc::Status s = done.get_future().get();
    std::vector<grpc::Slice> slices;
    reply.clear();
    if (s.ok() && out.Dump(&slices).ok()) {
      for (const auto& piece : slices) {
        reply.append(reinterpret_cast<const char*>(piece.begin()), piece.size());
      }
    }
    return s;
  });
  if (!status.ok()) return ToAbsl(status);
  return reply == std::string("\x08\x01", 2);  // HealthCheckResponse{status: SERVING}
}

absl::StatusOr<ServerMesh> GeodexClient::Upload(const std::string& file_name,
                                                const std::string& bytes, const std::string& alias,
                                                const std::string& expected_id,
                                                const std::optional<DemUploadOptions>& dem) {
  v1::Mesh mesh;
  grpc::Status status = Call(expected_id, [&](grpc::ClientContext* context) {
    auto writer = stub_->rpc->CreateMesh(context, &mesh);
    v1::CreateMeshRequest request;
    v1::CreateMeshMetadata* metadata = request.mutable_metadata();
    metadata->set_file_name(file_name);
    metadata->set_display_name(alias);
    metadata->set_expected_mesh_id(expected_id);
    metadata->set_total_bytes(bytes.size());
    if (dem.has_value()) {
      metadata->set_format(v1::MESH_FORMAT_GEOTIFF);
      *metadata->mutable_dem() = DemOptionsToProto(*dem);
    }
    bool ok = writer->Write(request);
    for (size_t offset = 0; ok && offset < bytes.size(); offset += options_.upload_chunk_bytes) {
      request.Clear();
      request.set_chunk(bytes.substr(offset, options_.upload_chunk_bytes));
      ok = writer->Write(request);
      if (options_.upload_progress) {
        options_.upload_progress(std::min<uint64_t>(bytes.size(), offset + request.chunk().size()),
                                 bytes.size());
      }
    }
    writer->WritesDone();
    return writer->Finish();
  });
  if (!status.ok()) return ToAbsl(status);
  return ServerMeshFromProto(mesh);
}

absl::StatusOr<ServerMesh> GeodexClient::GetMesh(const std::string& name) {
  v1::GetMeshRequest request;
  request.set_name(name);
  v1::Mesh mesh;
  const std::string id = IdOfName(name);
  grpc::Status status = Call(id, [&](grpc::ClientContext* context) {
    return stub_->rpc->GetMesh(context, request, &mesh);
  });
  if (!status.ok()) return ToAbsl(status);
  return ServerMeshFromProto(mesh);
}

absl::StatusOr<std::vector<ServerMesh>> GeodexClient::ListMeshes() {
  std::vector<ServerMesh> out;
  std::string token;
  do {
    v1::ListMeshesRequest request;
    request.set_page_size(1000);
    request.set_page_token(token);
    v1::ListMeshesResponse response;
    grpc::Status status = Call("", [&](grpc::ClientContext* context) {
      return stub_->rpc->ListMeshes(context, request, &response);
    });
    if (!status.ok()) return ToAbsl(status);
    for (const v1::Mesh& m : response.meshes()) out.push_back(ServerMeshFromProto(m));
    token = response.next_page_token();
  } while (!token.empty());
  return out;
}

absl::Status GeodexClient::DeleteMesh(const std::string& name) {
  v1::DeleteMeshRequest request;
  request.set_name(name);
  v1::DeleteMeshResponse response;
  const std::string id = IdOfName(name);
  return ToAbsl(Call(id, [&](grpc::ClientContext* context) {
    return stub_->rpc->DeleteMesh(context, request, &response);
  }));
}

absl::StatusOr<ServerMesh> GeodexClient::DeriveMesh(const std::string& name,
                                                    const BarrierOptions& barrier,
                                                    const std::string& alias) {
  v1::DeriveMeshRequest request;
  request.set_mesh(name);
  *request.mutable_barrier() = BarrierToProto(barrier);
  request.set_friction_geojson(barrier.friction_geojson);
  request.set_display_name(alias);
  v1::Mesh mesh;
  grpc::Status status = Call(IdOfName(name), [&](grpc::ClientContext* context) {
    return stub_->rpc->DeriveMesh(context, request, &mesh);
  });
  if (!status.ok()) return ToAbsl(status);
  return ServerMeshFromProto(mesh);
}

absl::StatusOr<MeshRef> GeodexClient::UploadIfAbsent(MeshRef ref) {
  absl::StatusOr<ServerMesh> existing = GetMesh(ref.name);
  if (existing.ok()) return ref;
  if (!absl::IsNotFound(existing.status())) return existing.status();
  absl::StatusOr<ServerMesh> uploaded = Upload(ref.file_name, ref.file_bytes, "", ref.id, ref.dem);
  if (!uploaded.ok()) return uploaded.status();
  ref.uploaded = true;
  return ref;
}

absl::StatusOr<MeshRef> GeodexClient::UploadMeshData(const std::string& file_name,
                                                     const MeshData& data) {
  MeshRef ref;
  ref.id = ComputeMeshId(data);
  ref.name = absl::StrCat("meshes/", ref.id);
  ref.file_bytes = MeshToOffText(data);
  ref.file_name = file_name;
  return UploadIfAbsent(std::move(ref));
}

absl::StatusOr<MeshRef> GeodexClient::ResolveDem(const std::string& path, const MeshData& mesh,
                                                 const DemUploadOptions& options) {
  MeshRef ref;
  ref.id = ComputeMeshId(mesh);
  ref.name = absl::StrCat("meshes/", ref.id);
  std::ifstream in(path, std::ios::binary);
  ref.file_bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  ref.file_name = std::filesystem::path(path).filename().string();
  ref.dem = options;
  absl::StatusOr<ServerMesh> existing = GetMesh(ref.name);
  if (existing.ok() && existing->has_terrain) return ref;
  if (!existing.ok() && !absl::IsNotFound(existing.status())) return existing.status();
  // Absent, or stored without its map (uploaded as a mesh file): the raster gives it.
  absl::StatusOr<ServerMesh> uploaded = Upload(ref.file_name, ref.file_bytes, "", ref.id, ref.dem);
  if (!uploaded.ok()) return uploaded.status();
  ref.uploaded = true;
  return ref;
}

absl::StatusOr<MeshRef> GeodexClient::ResolveMesh(const std::string& mesh) {
  MeshRef ref;
  std::error_code ec;
  if (mesh.rfind("sample:", 0) == 0) {
    absl::StatusOr<MeshData> data = MakeSampleMesh(mesh);
    if (!data.ok()) return data.status();
    return UploadMeshData(mesh.substr(7) + ".off", *data);
  }
  // A directory is a mesh name the server may know (a "terrain" directory beside "terrain" the
  // sample); if it does not, it fails as in local mode ("is a directory").
  const bool directory = std::filesystem::is_directory(mesh, ec);
  if (!directory && std::filesystem::exists(mesh, ec)) {
    absl::StatusOr<MeshData> data = ReadMeshFile(mesh);
    if (!data.ok()) return data.status();
    ref.id = ComputeMeshId(*data);
    ref.name = absl::StrCat("meshes/", ref.id);
    std::ifstream in(mesh, std::ios::binary);
    ref.file_bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    ref.file_name = std::filesystem::path(mesh).filename().string();
    return UploadIfAbsent(std::move(ref));
  }
  const std::string key = mesh.rfind("meshes/", 0) == 0 ? mesh.substr(7) : mesh;
  if (IsMeshId(key)) {
    ref.id = key;
    ref.name = absl::StrCat("meshes/", key);
    return ref;
  }
  absl::StatusOr<ServerMesh> found = GetMesh(absl::StrCat("meshes/", key));
  if (!found.ok()) {
    if (absl::IsNotFound(found.status()) || absl::IsInvalidArgument(found.status())) {
      if (directory) {
        return absl::InvalidArgumentError(absl::StrCat(mesh, ": is a directory, not a mesh file"));
      }
      return absl::NotFoundError(
          absl::StrCat(mesh, ": no such file, and the server has no mesh with that id or name"));
    }
    return found.status();
  }
  ref.name = found->name;
  ref.id = found->id();
  return ref;
}

template <typename Assembler, typename Start, typename OnMessage>
absl::Status GeodexClient::ReadStream(MeshRef& mesh, Start start, Assembler* out,
                                      OnMessage on_message, const CallOptions& options) {
  grpc::Status status = MeshCall(
      mesh,
      [&](grpc::ClientContext* context) {
        *out = Assembler();
        auto reader = start(context);
        typename Assembler::Message message;
        while (reader->Read(&message)) {
          out->Add(message);
          on_message(*out);
        }
        return reader->Finish();
      },
      options);
  return status.ok() ? absl::OkStatus() : ToAbsl(status);
}

namespace {
constexpr auto kNothing = [](const auto&) {};
}  // namespace

absl::StatusOr<DistanceField> GeodexClient::Field(MeshRef& mesh, const FieldQuery& query,
                                                  bool* cached, const CallOptions& call) {
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh(mesh.name);
  api::FieldQueryToProto(query, &request);
  SetMaxSnap(MaxSnap(call), &request);
  request.set_want_stats(true);
  api::FieldAssembler field;
  if (absl::Status s = ReadStream(
          mesh,
          [&](grpc::ClientContext* c) { return stub_->rpc->ComputeDistanceField(c, request); },
          &field, kNothing, call);
      !s.ok()) {
    return s;
  }
  if (cached != nullptr) *cached = field.cached();
  return std::move(field.result());
}

absl::StatusOr<MeshData> GeodexClient::GetMeshGeometry(MeshRef& mesh) {
  v1::GetMeshGeometryRequest request;
  request.set_name(mesh.name);
  api::MeshGeometryAssembler out;
  if (absl::Status s = ReadStream(
          mesh, [&](grpc::ClientContext* c) { return stub_->rpc->GetMeshGeometry(c, request); },
          &out, kNothing, CallOptions{});
      !s.ok()) {
    return s;
  }
  return std::move(out.result());
}

absl::StatusOr<PathQueryResult> GeodexClient::ShortestPath(MeshRef& mesh, const PathQuery& query,
                                                           const CallOptions& call) {
  v1::FindShortestPathRequest request;
  request.set_mesh(mesh.name);
  api::PathQueryToProto(query, &request);
  SetMaxSnap(MaxSnap(call), &request);
  request.set_want_stats(true);
  v1::FindShortestPathResponse response;
  grpc::Status status = MeshCall(
      mesh,
      [&](grpc::ClientContext* context) {
        return stub_->rpc->FindShortestPath(context, request, &response);
      },
      call);
  if (!status.ok()) return ToAbsl(status);
  return api::PathResultFromProto(response);
}

absl::StatusOr<DistanceMatrix> GeodexClient::Matrix(MeshRef& mesh, const MatrixQuery& query,
                                                    const CallOptions& call) {
  v1::ComputeDistanceMatrixRequest request;
  request.set_mesh(mesh.name);
  api::MatrixQueryToProto(query, &request);
  SetMaxSnap(MaxSnap(call), &request);
  request.set_want_stats(true);
  api::MatrixAssembler matrix;
  if (absl::Status s = ReadStream(
          mesh,
          [&](grpc::ClientContext* c) { return stub_->rpc->ComputeDistanceMatrix(c, request); },
          &matrix,
          [&](api::MatrixAssembler& m) {
            if (query.options.on_row && m.result().cols > 0) {
              query.options.on_row(m.rows_done(), m.result().rows);
            }
          },
          call);
      !s.ok()) {
    return s;
  }
  return std::move(matrix.result());
}

absl::StatusOr<PointDistances> GeodexClient::DistancesAtPoints(MeshRef& mesh,
                                                               const PointQuery& query,
                                                               PointDistanceMode mode,
                                                               const CallOptions& call) {
  v1::EstimateDistancesRequest request;
  request.set_mesh(mesh.name);
  api::PointQueryToProto(query, &request);
  SetMaxSnap(MaxSnap(call), &request);
  request.set_mode(ModeToProto(mode));
  v1::EstimateDistancesResponse response;
  grpc::Status status = MeshCall(
      mesh,
      [&](grpc::ClientContext* context) {
        return stub_->rpc->EstimateDistances(context, request, &response);
      },
      call);
  if (!status.ok()) return ToAbsl(status);
  PointDistances out;
  out.estimates = api::PointEstimatesFromProto(response);
  out.exact = api::PointValuesFromProto(response);
  out.snap_distances.assign(response.snap_distances().begin(), response.snap_distances().end());
  return out;
}

absl::StatusOr<std::vector<LocatedPoint>> GeodexClient::Locate(
    MeshRef& mesh, const std::vector<std::array<double, 3>>& xyz, double max_snap,
    const CallOptions& call) {
  v1::LocatePointsRequest request;
  request.set_mesh(mesh.name);
  for (const auto& q : xyz) api::PositionToProto(q, request.add_positions());
  SetMaxSnap(std::min(max_snap, MaxSnap(call)), &request);
  v1::LocatePointsResponse response;
  grpc::Status status = MeshCall(
      mesh,
      [&](grpc::ClientContext* context) {
        return stub_->rpc->LocatePoints(context, request, &response);
      },
      call);
  if (!status.ok()) return ToAbsl(status);
  std::vector<LocatedPoint> out;
  for (const auto& p : response.points()) out.push_back(api::LocatedPointFromProto(p));
  return out;
}

absl::StatusOr<Isolines> GeodexClient::ComputeIsolines(MeshRef& mesh, const IsolineQuery& query,
                                                       const CallOptions& call) {
  v1::ComputeIsolinesRequest request;
  request.set_mesh(mesh.name);
  api::IsolineQueryToProto(query, &request);
  SetMaxSnap(MaxSnap(call), &request);
  api::IsolinesAssembler out;
  if (absl::Status s = ReadStream(
          mesh, [&](grpc::ClientContext* c) { return stub_->rpc->ComputeIsolines(c, request); },
          &out, kNothing, call);
      !s.ok()) {
    return s;
  }
  return std::move(out.result());
}

absl::StatusOr<VoronoiDiagram> GeodexClient::ComputeVoronoi(MeshRef& mesh,
                                                            const VoronoiQuery& query,
                                                            const CallOptions& call) {
  v1::ComputeVoronoiRequest request;
  request.set_mesh(mesh.name);
  api::VoronoiQueryToProto(query, &request);
  SetMaxSnap(MaxSnap(call), &request);
  api::VoronoiAssembler out;
  if (absl::Status s = ReadStream(
          mesh, [&](grpc::ClientContext* c) { return stub_->rpc->ComputeVoronoi(c, request); },
          &out, kNothing, call);
      !s.ok()) {
    return s;
  }
  return std::move(out.result());
}

absl::StatusOr<DelaunayTriangulation> GeodexClient::ComputeDelaunay(MeshRef& mesh,
                                                                    const DelaunayQuery& query,
                                                                    const CallOptions& call) {
  v1::ComputeDelaunayRequest request;
  request.set_mesh(mesh.name);
  api::DelaunayQueryToProto(query, &request);
  SetMaxSnap(MaxSnap(call), &request);
  api::DelaunayAssembler out;
  if (absl::Status s = ReadStream(
          mesh, [&](grpc::ClientContext* c) { return stub_->rpc->ComputeDelaunay(c, request); },
          &out, kNothing, call);
      !s.ok()) {
    return s;
  }
  return std::move(out.result());
}

AsyncCall<PathQueryResult> GeodexClient::ShortestPathAsync(MeshRef mesh, PathQuery query,
                                                           CallOptions call) {
  return Async<PathQueryResult>(std::move(mesh), std::move(query), std::move(call),
                                [](GeodexClient& client, MeshRef& m, const PathQuery& q,
                                   const CallOptions& c) { return client.ShortestPath(m, q, c); });
}

AsyncCall<DistanceField> GeodexClient::FieldAsync(MeshRef mesh, FieldQuery query,
                                                  CallOptions call) {
  return Async<DistanceField>(std::move(mesh), std::move(query), std::move(call),
                              [](GeodexClient& client, MeshRef& m, const FieldQuery& q,
                                 const CallOptions& c) { return client.Field(m, q, nullptr, c); });
}

AsyncCall<PointDistances> GeodexClient::DistancesAtPointsAsync(MeshRef mesh, PointQuery query,
                                                               PointDistanceMode mode,
                                                               CallOptions call) {
  return Async<PointDistances>(
      std::move(mesh), std::move(query), std::move(call),
      [mode](GeodexClient& client, MeshRef& m, const PointQuery& q, const CallOptions& c) {
        return client.DistancesAtPoints(m, q, mode, c);
      });
}

AsyncCall<DistanceMatrix> GeodexClient::MatrixAsync(MeshRef mesh, MatrixQuery query,
                                                    CallOptions call) {
  return Async<DistanceMatrix>(std::move(mesh), std::move(query), std::move(call),
                               [](GeodexClient& client, MeshRef& m, const MatrixQuery& q,
                                  const CallOptions& c) { return client.Matrix(m, q, c); });
}

}  // namespace geodex::client
