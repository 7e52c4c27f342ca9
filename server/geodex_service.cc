#include "geodex_service.h"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "geodex/cancel.h"
#include "geodex/mesh_io.h"
#include "mesh_id.h"
#include "proto_convert.h"
#include "queries.h"
#include "query_reactors.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

constexpr int kDefaultPageSize = 50;
constexpr int kMaxPageSize = 1000;

absl::Status ValidateDisplayName(const std::string& name) {
  if (name.empty()) return absl::OkStatus();
  bool ok = name.size() <= 63 && !IsMeshId(name);
  for (char c : name) {
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '.' || c == '_' || c == '-');
  }
  if (!ok) {
    return absl::InvalidArgumentError(
        absl::StrCat("metadata.display_name: \"", name,
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
        Finish(ToGrpcStatus(absl::InvalidArgumentError(
            "metadata: the first CreateMeshRequest must carry metadata")));
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
        Finish(ToGrpcStatus(absl::InvalidArgumentError(
            "metadata.expected_mesh_id: must be 64 lowercase hex digits")));
        return;
      }
      if (metadata_.total_bytes() > service_->limits().max_upload_bytes) {
        Finish(TooLarge(metadata_.total_bytes()));
        return;
      }
      bytes_.reserve(metadata_.total_bytes());
    } else if (request_.has_metadata()) {
      Finish(ToGrpcStatus(absl::InvalidArgumentError(
          "metadata: only the first CreateMeshRequest may carry metadata")));
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
    return ToGrpcStatus(absl::ResourceExhaustedError(
        absl::StrCat("upload of ", bytes,
                     " bytes exceeds --max_upload_bytes=", service_->limits().max_upload_bytes)));
  }

  void EndOfUpload() {
    if (context_->IsCancelled()) {
      Finish(CancelledStatus());
      return;
    }
    if (!have_metadata_) {
      Finish(ToGrpcStatus(absl::InvalidArgumentError("metadata: the upload stream was empty")));
      return;
    }
    if (!service_->pool()->TrySubmit([this] { Build(); }))
      Finish(PoolFullStatus(*service_->pool()));
  }

  // On the pool.
  void Build() {
    if (cancel_.IsCancelled()) {
      service_->pool()->ReleaseWorker();
      Finish(CancelledStatus());
      return;
    }
    const absl::Status status = BuildAndStore();
    service_->pool()->ReleaseWorker();  // before Finish (see ComputePool::ReleaseWorker)
    Finish(ToGrpcStatus(status));
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
      return absl::ResourceExhaustedError(
          absl::StrCat("mesh has ", data->vertex_count(),
                       " vertices, over --max_vertices=", limits.max_vertices));
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
    const std::string canonical =
        service_->store()->has_disk() && candidate->mesh != nullptr ? CanonicalMeshEncoding(*data)
                                                                    : std::string();
    absl::StatusOr<std::shared_ptr<const StoredMesh>> stored =
        service_->store()->Insert(std::move(candidate), canonical);
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

}  // namespace

grpc::ServerReadReactor<v1::CreateMeshRequest>* GeodexService::CreateMesh(
    grpc::CallbackServerContext* context, v1::Mesh* response) {
  if (!auth_.Allows(*context)) {
    return new RejectedReadReactor<v1::CreateMeshRequest>(UnauthenticatedStatus());
  }
  return new CreateMeshReactor(this, context, response);
}

// Get/List/Delete are map look-ups under the store's mutex (Delete also unlinks a file): answered
// inline.
grpc::ServerUnaryReactor* GeodexService::GetMesh(grpc::CallbackServerContext* context,
                                                 const v1::GetMeshRequest* request,
                                                 v1::Mesh* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  if (!auth_.Allows(*context)) {
    reactor->Finish(UnauthenticatedStatus());
    return reactor;
  }
  absl::StatusOr<std::string> key = ParseMeshName(request->name(), "name");
  absl::Status status = key.status();
  if (key.ok()) {
    // The record: a mesh that is only on disk is described without loading it.
    absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = store_->GetRecord(*key);
    if (mesh.ok()) {
      MeshToProto(**mesh, response);
    } else {
      status = absl::NotFoundError(absl::StrCat("name: mesh \"", request->name(), "\" not found"));
    }
  }
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

grpc::ServerUnaryReactor* GeodexService::ListMeshes(grpc::CallbackServerContext* context,
                                                    const v1::ListMeshesRequest* request,
                                                    v1::ListMeshesResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  if (!auth_.Allows(*context)) {
    reactor->Finish(UnauthenticatedStatus());
    return reactor;
  }
  if (request->page_size() < 0) {
    reactor->Finish(ToGrpcStatus(absl::InvalidArgumentError(
        absl::StrCat("page_size: must be >= 0, got ", request->page_size()))));
    return reactor;
  }
  if (!request->page_token().empty() && !IsMeshId(request->page_token())) {
    reactor->Finish(
        ToGrpcStatus(absl::InvalidArgumentError("page_token: not a token returned by ListMeshes")));
    return reactor;
  }
  int page_size =
      request->page_size() == 0 ? kDefaultPageSize : std::min(request->page_size(), kMaxPageSize);
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
  if (!auth_.Allows(*context)) {
    reactor->Finish(UnauthenticatedStatus());
    return reactor;
  }
  absl::StatusOr<std::string> key = ParseMeshName(request->name(), "name");
  absl::Status status = key.status();
  if (key.ok()) {
    status = store_->Delete(*key);
    if (absl::IsNotFound(status)) {
      status = absl::NotFoundError(absl::StrCat("name: mesh \"", request->name(), "\" not found"));
    }
  }
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

// Queries: the reactor templates run the query functions of queries.cc on the pool.
grpc::ServerWriteReactor<v1::ComputeDistanceFieldResponse>* GeodexService::ComputeDistanceField(
    grpc::CallbackServerContext* context, const v1::ComputeDistanceFieldRequest* request) {
  if (!auth_.Allows(*context)) {
    return new RejectedWriteReactor<v1::ComputeDistanceFieldResponse>(UnauthenticatedStatus());
  }
  return StreamQueryReactor<v1::ComputeDistanceFieldRequest,
                            v1::ComputeDistanceFieldResponse>::Start(env(),
                                                                     &RunComputeDistanceField,
                                                                     request);
}

grpc::ServerUnaryReactor* GeodexService::FindShortestPath(
    grpc::CallbackServerContext* context, const v1::FindShortestPathRequest* request,
    v1::FindShortestPathResponse* response) {
  if (!auth_.Allows(*context)) {
    grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
    reactor->Finish(UnauthenticatedStatus());
    return reactor;
  }
  return UnaryQueryReactor<v1::FindShortestPathRequest, v1::FindShortestPathResponse>::Start(
      env(), &RunFindShortestPath, request, response);
}

grpc::ServerWriteReactor<v1::ComputeDistanceMatrixResponse>* GeodexService::ComputeDistanceMatrix(
    grpc::CallbackServerContext* context, const v1::ComputeDistanceMatrixRequest* request) {
  if (!auth_.Allows(*context)) {
    return new RejectedWriteReactor<v1::ComputeDistanceMatrixResponse>(UnauthenticatedStatus());
  }
  return StreamQueryReactor<v1::ComputeDistanceMatrixRequest,
                            v1::ComputeDistanceMatrixResponse>::Start(env(),
                                                                      &RunComputeDistanceMatrix,
                                                                      request);
}

grpc::ServerUnaryReactor* GeodexService::EstimateDistances(
    grpc::CallbackServerContext* context, const v1::EstimateDistancesRequest* request,
    v1::EstimateDistancesResponse* response) {
  if (!auth_.Allows(*context)) {
    grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
    reactor->Finish(UnauthenticatedStatus());
    return reactor;
  }
  return UnaryQueryReactor<v1::EstimateDistancesRequest, v1::EstimateDistancesResponse>::Start(
      env(), &RunEstimateDistances, request, response);
}

grpc::ServerUnaryReactor* GeodexService::LocatePoints(grpc::CallbackServerContext* context,
                                                      const v1::LocatePointsRequest* request,
                                                      v1::LocatePointsResponse* response) {
  if (!auth_.Allows(*context)) {
    grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
    reactor->Finish(UnauthenticatedStatus());
    return reactor;
  }
  return UnaryQueryReactor<v1::LocatePointsRequest, v1::LocatePointsResponse>::Start(
      env(), &RunLocatePoints, request, response);
}

grpc::ServerWriteReactor<v1::ComputeIsolinesResponse>* GeodexService::ComputeIsolines(
    grpc::CallbackServerContext* context, const v1::ComputeIsolinesRequest* request) {
  if (!auth_.Allows(*context)) {
    return new RejectedWriteReactor<v1::ComputeIsolinesResponse>(UnauthenticatedStatus());
  }
  return StreamQueryReactor<v1::ComputeIsolinesRequest, v1::ComputeIsolinesResponse>::Start(
      env(), &RunComputeIsolines, request);
}

grpc::ServerWriteReactor<v1::ComputeVoronoiResponse>* GeodexService::ComputeVoronoi(
    grpc::CallbackServerContext* context, const v1::ComputeVoronoiRequest* request) {
  if (!auth_.Allows(*context)) {
    return new RejectedWriteReactor<v1::ComputeVoronoiResponse>(UnauthenticatedStatus());
  }
  return StreamQueryReactor<v1::ComputeVoronoiRequest, v1::ComputeVoronoiResponse>::Start(
      env(), &RunComputeVoronoi, request);
}

grpc::ServerWriteReactor<v1::ComputeDelaunayResponse>* GeodexService::ComputeDelaunay(
    grpc::CallbackServerContext* context, const v1::ComputeDelaunayRequest* request) {
  if (!auth_.Allows(*context)) {
    return new RejectedWriteReactor<v1::ComputeDelaunayResponse>(UnauthenticatedStatus());
  }
  return StreamQueryReactor<v1::ComputeDelaunayRequest, v1::ComputeDelaunayResponse>::Start(
      env(), &RunComputeDelaunay, request);
}

}  // namespace geodex::server
