#include "geodex_service.h"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "geodex/cancel.h"
#include "geodex/mesh_io.h"
#include "geodex/shortest_path.h"
#include "mesh_id.h"
#include "proto_convert.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

constexpr int kDefaultPageSize = 50;
constexpr int kMaxPageSize = 1000;

grpc::Status PoolFull(const ComputePool& pool) {
  return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                      absl::StrCat("compute queue full (", pool.threads(), " workers busy, ",
                                   pool.queue_capacity(),
                                   " queued; --pool_threads/--queue_capacity); retry later"));
}

grpc::Status Cancelled() {
  return grpc::Status(grpc::StatusCode::CANCELLED, "call cancelled or deadline exceeded");
}

absl::Status ValidateDisplayName(const std::string& name) {
  if (name.empty()) return absl::OkStatus();
  bool ok = name.size() <= 63 && !IsMeshId(name);
  for (char c : name) {
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '.' || c == '_' || c == '-');
  }
  if (!ok) {
    return absl::InvalidArgumentError(absl::StrCat(
        "metadata.display_name: \"", name,
        "\" must be 1-63 characters of [A-Za-z0-9._-] and not a 64-digit hex id"));
  }
  return absl::OkStatus();
}

MeshFormat FormatFromProto(v1::MeshFormat format) {
  switch (format) {
    case v1::MESH_FORMAT_OFF:
      return MeshFormat::kOff;
    case v1::MESH_FORMAT_OBJ:
      return MeshFormat::kObj;
    case v1::MESH_FORMAT_PLY:
      return MeshFormat::kPly;
    case v1::MESH_FORMAT_STL:
      return MeshFormat::kStl;
    default:
      return MeshFormat::kAuto;
  }
}

// Looks up the request's mesh: InvalidArgument for a malformed name, NotFound for an unknown one.
absl::StatusOr<std::shared_ptr<const StoredMesh>> LookupMesh(MeshStore& store,
                                                             const std::string& name,
                                                             const std::string& field) {
  absl::StatusOr<std::string> key = ParseMeshName(name, field);
  if (!key.ok()) return key.status();
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = store.Get(*key);
  if (!mesh.ok()) {
    return absl::NotFoundError(absl::StrCat(field, ": mesh \"", name, "\" not found"));
  }
  return mesh;
}

// ------------------------------------------------------------------------------------------
// CreateMesh: reads chunks on gRPC's threads (appending bytes only), parses and builds on the pool.
class CreateMeshReactor final : public grpc::ServerReadReactor<v1::CreateMeshRequest> {
 public:
  CreateMeshReactor(GeodexService* service, grpc::CallbackServerContext* context,
                    v1::Mesh* response)
      : service_(service), context_(context), response_(response) {
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // end of the client's stream (or the call broke)
      EndOfUpload();
      return;
    }
    if (!have_metadata_) {
      if (!request_.has_metadata()) {
        Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            "metadata: the first CreateMeshRequest must carry metadata"));
        return;
      }
      metadata_ = request_.metadata();
      have_metadata_ = true;
      absl::Status valid = ValidateDisplayName(metadata_.display_name());
      if (!valid.ok()) {
        Finish(ToGrpcStatus(valid));
        return;
      }
      if (!metadata_.expected_mesh_id().empty() && !IsMeshId(metadata_.expected_mesh_id())) {
        Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            "metadata.expected_mesh_id: must be 64 lowercase hex digits"));
        return;
      }
      if (metadata_.total_bytes() > service_->limits().max_upload_bytes) {
        Finish(TooLarge(metadata_.total_bytes()));
        return;
      }
      bytes_.reserve(metadata_.total_bytes());
    } else if (request_.has_metadata()) {
      Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "metadata: only the first CreateMeshRequest may carry metadata"));
      return;
    } else {
      const std::string& chunk = request_.chunk();
      if (bytes_.size() + chunk.size() > service_->limits().max_upload_bytes) {
        Finish(TooLarge(bytes_.size() + chunk.size()));
        return;
      }
      bytes_.append(chunk);
    }
    StartRead(&request_);
  }

  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  grpc::Status TooLarge(uint64_t bytes) const {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        absl::StrCat("upload of ", bytes, " bytes exceeds --max_upload_bytes=",
                                     service_->limits().max_upload_bytes));
  }

  void EndOfUpload() {
    if (context_->IsCancelled()) {
      Finish(Cancelled());
      return;
    }
    if (!have_metadata_) {
      Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "metadata: the upload stream was empty"));
      return;
    }
    if (!service_->pool()->TrySubmit([this] { Build(); })) Finish(PoolFull(*service_->pool()));
  }

  // On the pool.
  void Build() {
    if (cancel_.IsCancelled()) {
      Finish(Cancelled());
      return;
    }
    Finish(ToGrpcStatus(BuildAndStore()));
  }

  absl::Status BuildAndStore() {
    const ServiceLimits& limits = service_->limits();
    ReadLimits read_limits;
    read_limits.max_vertices = limits.max_vertices;
    read_limits.max_faces = limits.max_faces;
    std::string file_name = metadata_.file_name().empty() ? "upload" : metadata_.file_name();
    absl::StatusOr<MeshData> data = ReadMeshFromBuffer(
        absl::string_view(bytes_), FormatFromProto(metadata_.format()), file_name, read_limits);
    if (!data.ok()) {
      if (data.status().code() == absl::StatusCode::kResourceExhausted) return data.status();
      return absl::InvalidArgumentError(absl::StrCat("chunk: ", data.status().message()));
    }
    if (data->vertex_count() > limits.max_vertices) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "mesh has ", data->vertex_count(), " vertices, over --max_vertices=", limits.max_vertices));
    }
    if (data->face_count() > limits.max_faces) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "mesh has ", data->face_count(), " faces, over --max_faces=", limits.max_faces));
    }
    std::string id = ComputeMeshId(*data);
    if (!metadata_.expected_mesh_id().empty() && metadata_.expected_mesh_id() != id) {
      return absl::InvalidArgumentError(
          absl::StrCat("metadata.expected_mesh_id: ", metadata_.expected_mesh_id(),
                       " differs from the uploaded mesh's id ", id));
    }
    std::shared_ptr<StoredMesh> candidate;
    if (service_->store()->Contains(id)) {
      // Idempotent re-upload: no rebuild. (Insert adds a new alias to the stored mesh.)
      candidate = std::make_shared<StoredMesh>();
      candidate->id = id;
    } else {
      MeshBuildOptions build_options;
      build_options.strict = metadata_.strict();
      absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data, build_options);
      if (!mesh.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("chunk: ", mesh.status().message()));
      }
      if (cancel_.IsCancelled()) return absl::CancelledError("upload cancelled");
      candidate = MakeStoredMesh(id, *std::move(mesh));
      candidate->upload_bytes = bytes_.size();
      candidate->pinned = metadata_.pin();
    }
    candidate->display_name = metadata_.display_name();
    absl::StatusOr<std::shared_ptr<const StoredMesh>> stored =
        service_->store()->Insert(std::move(candidate));
    if (!stored.ok()) return stored.status();
    MeshToProto(**stored, response_);
    return absl::OkStatus();
  }

  GeodexService* service_;
  grpc::CallbackServerContext* context_;
  v1::Mesh* response_;
  v1::CreateMeshRequest request_;
  v1::CreateMeshMetadata metadata_;
  bool have_metadata_ = false;
  std::string bytes_;
  CancelToken cancel_;
};

// ------------------------------------------------------------------------------------------
// ComputeDistanceField: solves on the pool, then streams chunks (each StartWrite after the
// previous write completed).
class DistanceFieldReactor final
    : public grpc::ServerWriteReactor<v1::ComputeDistanceFieldResponse> {
 public:
  DistanceFieldReactor(GeodexService* service, const v1::ComputeDistanceFieldRequest* request)
      : service_(service), request_(request) {}

  void Start() {
    if (!service_->pool()->TrySubmit([this] { Solve(); })) Finish(PoolFull(*service_->pool()));
  }

  void OnWriteDone(bool ok) override {
    if (!ok) {
      Finish(Cancelled());
      return;
    }
    WriteNext();
  }
  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  // On the pool.
  void Solve() {
    if (cancel_.IsCancelled()) {
      Finish(Cancelled());
      return;
    }
    absl::Status status = Compute();
    if (!status.ok()) {
      Finish(ToGrpcStatus(status));
      return;
    }
    WriteNext();
  }

  absl::Status Compute() {
    const ServiceLimits& limits = service_->limits();
    absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
        LookupMesh(*service_->store(), request_->mesh(), "mesh");
    if (!mesh.ok()) return mesh.status();
    if (request_->sources_size() == 0) {
      return absl::InvalidArgumentError("sources: at least one source is required");
    }
    if (static_cast<uint64_t>(request_->sources_size()) > limits.max_sources) {
      return absl::ResourceExhaustedError(absl::StrCat("sources: ", request_->sources_size(),
                                                       " sources, over --max_sources=",
                                                       limits.max_sources));
    }
    if ((*mesh)->vertex_count > limits.max_output_values) {
      return absl::ResourceExhaustedError(
          absl::StrCat("the field has ", (*mesh)->vertex_count,
                       " values, over --max_output_values=", limits.max_output_values));
    }
    if (!v1::ValueType_IsValid(request_->value_type())) {
      return absl::InvalidArgumentError(
          absl::StrCat("value_type: unknown value ", request_->value_type()));
    }
    std::vector<SurfacePoint> sources;
    sources.reserve(request_->sources_size());
    for (int i = 0; i < request_->sources_size(); ++i) {
      absl::StatusOr<SurfacePoint> p =
          ResolvePoint(**mesh, request_->sources(i), absl::StrCat("sources[", i, "]"));
      if (!p.ok()) return p.status();
      sources.push_back(*p);
    }
    absl::StatusOr<GeodesicOptions> options =
        SolverOptionsFromProto(request_->options(), limits.max_windows, "options");
    if (!options.ok()) return options.status();
    options->cancel = &cancel_;
    absl::StatusOr<DistanceField> field = ComputeDistanceField(*(*mesh)->mesh, sources, *options);
    if (!field.ok()) {
      if (field.status().code() == absl::StatusCode::kInvalidArgument) {
        return absl::InvalidArgumentError(absl::StrCat("sources: ", field.status().message()));
      }
      return field.status();
    }
    distances_ = std::move(field->distance);
    if (!request_->omit_labels()) labels_ = std::move(field->source);
    stats_ = field->stats;
    sources_ = std::move(sources);
    return absl::OkStatus();
  }

  void WriteNext() {
    const size_t n = distances_.size();
    if (started_ && next_ >= n) {
      Finish(grpc::Status::OK);
      return;
    }
    response_.Clear();
    response_.set_vertex_count(n);
    response_.set_offset(next_);
    if (!started_) {
      for (const SurfacePoint& p : sources_) SurfacePointToProto(p, response_.add_resolved_sources());
    }
    const size_t end = std::min(n, next_ + std::max<size_t>(1, service_->limits().field_chunk_values));
    if (request_->value_type() == v1::VALUE_TYPE_FLOAT32) {
      auto* out = response_.mutable_distances_f32();
      out->Reserve(static_cast<int>(end - next_));
      for (size_t i = next_; i < end; ++i) out->AddAlreadyReserved(static_cast<float>(distances_[i]));
    } else {
      response_.mutable_distances_f64()->Add(distances_.begin() + next_, distances_.begin() + end);
    }
    if (!labels_.empty()) {
      response_.mutable_labels()->Add(labels_.begin() + next_, labels_.begin() + end);
    }
    if (end == n && request_->want_stats()) StatsToProto(stats_, response_.mutable_stats());
    started_ = true;
    next_ = end;
    StartWrite(&response_);
  }

  GeodexService* service_;
  const v1::ComputeDistanceFieldRequest* request_;
  CancelToken cancel_;
  std::vector<double> distances_;
  std::vector<uint32_t> labels_;
  std::vector<SurfacePoint> sources_;
  SolveStats stats_;
  size_t next_ = 0;
  bool started_ = false;
  v1::ComputeDistanceFieldResponse response_;
};

// ------------------------------------------------------------------------------------------
// FindShortestPath: one solve on the pool.
class ShortestPathReactor final : public grpc::ServerUnaryReactor {
 public:
  ShortestPathReactor(GeodexService* service, const v1::FindShortestPathRequest* request,
                      v1::FindShortestPathResponse* response)
      : service_(service), request_(request), response_(response) {}

  void Start() {
    if (!service_->pool()->TrySubmit([this] { Solve(); })) Finish(PoolFull(*service_->pool()));
  }
  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  void Solve() {
    if (cancel_.IsCancelled()) {
      Finish(Cancelled());
      return;
    }
    Finish(ToGrpcStatus(Compute()));
  }

  absl::Status Compute() {
    absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
        LookupMesh(*service_->store(), request_->mesh(), "mesh");
    if (!mesh.ok()) return mesh.status();
    absl::StatusOr<SurfacePoint> from = ResolvePoint(**mesh, request_->from(), "from");
    if (!from.ok()) return from.status();
    absl::StatusOr<SurfacePoint> to = ResolvePoint(**mesh, request_->to(), "to");
    if (!to.ok()) return to.status();
    PathQueryOptions options;
    absl::StatusOr<GeodesicOptions> solver =
        SolverOptionsFromProto(request_->options(), service_->limits().max_windows, "options");
    if (!solver.ok()) return solver.status();
    options.solver = *solver;
    options.solver.cancel = &cancel_;
    absl::StatusOr<PathQueryResult> result =
        ComputeShortestPath(*(*mesh)->mesh, *from, *to, options);
    if (!result.ok()) {
      if (result.status().code() == absl::StatusCode::kInvalidArgument) {
        return absl::InvalidArgumentError(absl::StrCat("from/to: ", result.status().message()));
      }
      if (result.status().code() == absl::StatusCode::kNotFound) {
        return absl::NotFoundError(absl::StrCat("to: unreachable from `from` (",
                                                result.status().message(), ")"));
      }
      return result.status();
    }
    response_->set_distance(result->distance);
    for (const PathPoint& p : result->path.points) {
      v1::PathPoint* out = response_->add_points();
      out->mutable_position()->set_x(p.position[0]);
      out->mutable_position()->set_y(p.position[1]);
      out->mutable_position()->set_z(p.position[2]);
      SurfacePointToProto(p.where, out->mutable_where());
    }
    if (request_->want_stats()) StatsToProto(result->stats, response_->mutable_stats());
    return absl::OkStatus();
  }

  GeodexService* service_;
  const v1::FindShortestPathRequest* request_;
  v1::FindShortestPathResponse* response_;
  CancelToken cancel_;
};

}  // namespace

grpc::ServerReadReactor<v1::CreateMeshRequest>* GeodexService::CreateMesh(
    grpc::CallbackServerContext* context, v1::Mesh* response) {
  return new CreateMeshReactor(this, context, response);
}

// Get/List/Delete are map look-ups under the store's mutex: answered inline.
grpc::ServerUnaryReactor* GeodexService::GetMesh(grpc::CallbackServerContext* context,
                                                 const v1::GetMeshRequest* request,
                                                 v1::Mesh* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh =
      LookupMesh(*store_, request->name(), "name");
  if (mesh.ok()) MeshToProto(**mesh, response);
  reactor->Finish(ToGrpcStatus(mesh.status()));
  return reactor;
}

grpc::ServerUnaryReactor* GeodexService::ListMeshes(grpc::CallbackServerContext* context,
                                                    const v1::ListMeshesRequest* request,
                                                    v1::ListMeshesResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  if (request->page_size() < 0) {
    reactor->Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                 absl::StrCat("page_size: must be >= 0, got ", request->page_size())));
    return reactor;
  }
  if (!request->page_token().empty() && !IsMeshId(request->page_token())) {
    reactor->Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                 "page_token: not a token returned by ListMeshes"));
    return reactor;
  }
  int page_size = request->page_size() == 0 ? kDefaultPageSize
                                            : std::min(request->page_size(), kMaxPageSize);
  bool more = false;
  std::vector<std::shared_ptr<const StoredMesh>> page =
      store_->List(request->page_token(), static_cast<size_t>(page_size), &more);
  for (const auto& mesh : page) MeshToProto(*mesh, response->add_meshes());
  if (more && !page.empty()) response->set_next_page_token(page.back()->id);
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* GeodexService::DeleteMesh(grpc::CallbackServerContext* context,
                                                    const v1::DeleteMeshRequest* request,
                                                    v1::DeleteMeshResponse* /*response*/) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::StatusOr<std::string> key = ParseMeshName(request->name(), "name");
  absl::Status status = key.status();
  if (key.ok()) {
    status = store_->Delete(*key);
    if (!status.ok()) {
      status = absl::NotFoundError(absl::StrCat("name: mesh \"", request->name(), "\" not found"));
    }
  }
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

grpc::ServerWriteReactor<v1::ComputeDistanceFieldResponse>* GeodexService::ComputeDistanceField(
    grpc::CallbackServerContext* /*context*/, const v1::ComputeDistanceFieldRequest* request) {
  auto* reactor = new DistanceFieldReactor(this, request);
  reactor->Start();
  return reactor;
}

grpc::ServerUnaryReactor* GeodexService::FindShortestPath(
    grpc::CallbackServerContext* /*context*/, const v1::FindShortestPathRequest* request,
    v1::FindShortestPathResponse* response) {
  auto* reactor = new ShortestPathReactor(this, request, response);
  reactor->Start();
  return reactor;
}

}  // namespace geodex::server
