#include "geodex_service.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "geodex/cancel.h"
#include "geodex/limits.h"
#include "geodex/mesh_id.h"
#include "geodex/mesh_io.h"
#include "geodex/terrain.h"
#include "google/protobuf/descriptor.h"
#include "grpcpp/support/server_callback.h"
#include "proto_convert.h"
#include "queries.h"
#include "query_reactors.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

// MESH_FORMAT_GEOTIFF is not a mesh file format: a DEM (the reactor reads it through terrain/).
absl::StatusOr<MeshFormat> FormatFromProto(int format) {
  switch (format) {
    case v1::MESH_FORMAT_GEOTIFF:
    case v1::MESH_FORMAT_UNSPECIFIED:
      return MeshFormat::kAuto;
    case v1::MESH_FORMAT_OFF:
      return MeshFormat::kOff;
    case v1::MESH_FORMAT_OBJ:
      return MeshFormat::kObj;
    case v1::MESH_FORMAT_PLY:
      return MeshFormat::kPly;
    case v1::MESH_FORMAT_STL:
      return MeshFormat::kStl;
    default:
      return FieldError("metadata.format", absl::StrCat("unknown value ", format));
  }
}

// ------------------------------------------------------------------------------------------
// CreateMesh: reads chunks on gRPC's threads (appending bytes only), parses and builds on the pool.
// Nothing is stored unless the whole stream arrived intact: every message parses, the first and
// only the first carries metadata, and the byte count matches metadata.total_bytes when given.
class CreateMeshReactor final : public grpc::ServerReadReactor<grpc::ByteBuffer> {
 public:
  CreateMeshReactor(const ReactorEnv& env, grpc::CallbackServerContext* context,
                    grpc::ByteBuffer* response)
      : env_(env), context_(context), response_(response) {
    if (!env_.auth->Allows(*context)) {
      Finish(UnauthenticatedStatus());
      return;
    }
    StartRead(&message_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // end of the client's stream (or the call broke)
      EndOfUpload();
      return;
    }
    absl::Status status;
    {
      // Successive reads may complete on different gRPC threads: the lock makes their order
      // visible (to ThreadSanitizer too; gRPC's own hand-off is in an uninstrumented library).
      std::lock_guard<std::mutex> lock(mu_);
      ++messages_;
      v1::CreateMeshRequest request;
      const std::string what = absl::StrCat("message ", messages_, " of the upload stream");
      status = ParseRequest(message_, &request, what.c_str());
      if (!status.ok()) {
        status = absl::InvalidArgumentError(
            absl::StrCat(status.message(), "; nothing was stored, upload the mesh again"));
      } else {
        message_.Clear();
        status = Accept(request);
      }
    }
    if (!status.ok()) {
      Fail(status);
      return;
    }
    StartRead(&message_);
  }

  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }

 private:
  // Never called with mu_ held: Finish may run OnDone (and delete this) at once.
  void Fail(const absl::Status& status) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      bytes_.clear();
      bytes_.shrink_to_fit();
    }
    Finish(ToGrpcStatus(status));
  }

  absl::Status Accept(const v1::CreateMeshRequest& request) {
    const ServiceLimits& limits = *env_.limits;
    if (!have_metadata_) {
      if (!request.has_metadata()) {
        return FieldError("metadata", "the first CreateMeshRequest must carry metadata");
      }
      metadata_ = request.metadata();
      have_metadata_ = true;
      if (env_.descriptions != nullptr) {
        env_.descriptions->SetMesh(context_, metadata_.display_name());
      }
      if (absl::Status valid =
              ValidateDisplayName(metadata_.display_name(), "metadata.display_name");
          !valid.ok()) {
        return valid;
      }
      absl::StatusOr<MeshFormat> format = FormatFromProto(metadata_.format());
      if (!format.ok()) return format.status();
      format_ = *format;
      // A DEM: said so, or guessed from the name now (from the bytes' TIFF header at the end).
      dem_ = metadata_.format() == v1::MESH_FORMAT_GEOTIFF ||
             (metadata_.format() == v1::MESH_FORMAT_UNSPECIFIED &&
              terrain::IsGeoTiffPath(metadata_.file_name()));
      if (metadata_.has_dem()) {
        if (metadata_.format() != v1::MESH_FORMAT_GEOTIFF &&
            metadata_.format() != v1::MESH_FORMAT_UNSPECIFIED) {
          return FieldError("metadata.dem",
                            "DEM options are for a GeoTIFF upload (format MESH_FORMAT_GEOTIFF)");
        }
        if (metadata_.dem().has_barrier_below() &&
            !std::isfinite(metadata_.dem().barrier_below())) {
          return FieldError("metadata.dem.barrier_below", "must be finite");
        }
        // Terrain's one check of the values, before any byte is received.
        if (absl::Status s = terrain::ValidateDemOptions(DemOptionsOf(metadata_.dem())); !s.ok()) {
          return FieldError(absl::StrCat("metadata.dem.", InvalidOptionOf(s)), s.message());
        }
      }
      if (!metadata_.expected_mesh_id().empty() && !IsMeshId(metadata_.expected_mesh_id())) {
        return FieldError("metadata.expected_mesh_id", "must be 64 lowercase hex digits");
      }
      if (metadata_.total_bytes() > limits.max_upload_bytes) {
        return TooLarge(metadata_.total_bytes());
      }
      bytes_.reserve(metadata_.total_bytes());
      return absl::OkStatus();
    }
    if (request.has_metadata()) {
      return FieldError(
          "metadata",
          absl::StrCat("message ", messages_,
                       " carries metadata again; only the first CreateMeshRequest may"));
    }
    if (request.payload_case() != v1::CreateMeshRequest::kChunk) {
      return FieldError("chunk",
                        absl::StrCat("message ", messages_,
                                     " of the upload stream carries neither metadata nor a chunk"));
    }
    const std::string& chunk = request.chunk();
    const uint64_t total = bytes_.size() + chunk.size();
    if (total > limits.max_upload_bytes) return TooLarge(total);
    if (metadata_.total_bytes() != 0 && total > metadata_.total_bytes()) {
      return FieldError("metadata.total_bytes",
                        absl::StrCat("declared ", metadata_.total_bytes(), " bytes, but message ",
                                     messages_, " brings the upload to ", total));
    }
    bytes_.append(chunk);
    return absl::OkStatus();
  }

  absl::Status TooLarge(uint64_t bytes) const {
    return ServerLimitError("max_upload_bytes",
                            absl::StrCat("upload of ", bytes, " bytes exceeds --max_upload_bytes=",
                                         env_.limits->max_upload_bytes));
  }

  void EndOfUpload() {
    if (context_->IsCancelled()) {
      Finish(CancelledStatus());
      return;
    }
    absl::Status complete;
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (!have_metadata_) {
        complete = FieldError("metadata", "the upload stream was empty");
      } else if (metadata_.total_bytes() != 0 && bytes_.size() != metadata_.total_bytes()) {
        complete = FieldError("metadata.total_bytes",
                              absl::StrCat("declared ", metadata_.total_bytes(), " bytes, but ",
                                           bytes_.size(), " arrived; nothing was stored"));
      } else if (bytes_.empty()) {
        complete = FieldError(
            "chunk", absl::StrCat("the upload stream ended after the metadata without any bytes (",
                                  messages_, " messages)"));
      }
    }
    if (!complete.ok()) {
      Fail(complete);
      return;
    }
    if (!env_.pool->TrySubmit([this] { Build(); })) {
      Fail(PoolFullError(*env_.pool, "--pool_threads/--queue_capacity"));
    }
  }

  // On the pool.
  void Build() {
    if (cancel_.IsCancelled()) {
      env_.pool->ReleaseWorker();
      Finish(CancelledStatus());
      return;
    }
    v1::Mesh mesh;
    absl::Status status;
    {
      std::lock_guard<std::mutex> lock(mu_);
      status = BuildAndStore(&mesh);
      bytes_.clear();
      bytes_.shrink_to_fit();
    }
    if (status.ok()) SerializeResponse(mesh, response_);
    env_.pool->ReleaseWorker();  // before Finish (see ComputePool::ReleaseWorker)
    Finish(ToGrpcStatus(status));
  }

  // The DEM options an upload's metadata asks for (step 0: every cell).
  static terrain::DemOptions DemOptionsOf(const v1::DemOptions& dem) {
    terrain::DemOptions options;
    options.step = std::max<uint32_t>(1, dem.step());
    if (dem.has_barrier_below()) options.barrier_below = dem.barrier_below();
    options.z_tolerance = dem.z_tolerance();
    return options;
  }

  // A GeoTIFF upload's mesh, through GDAL's GTiff driver only, at most --max_dem_cells cells.
  absl::StatusOr<terrain::Dem> ReadDem(const std::string& file_name) const {
    terrain::DemOptions options = DemOptionsOf(metadata_.dem());
    options.max_cells = env_.limits->max_dem_cells;
    options.cancel = &cancel_;  // the call's: a cancelled upload stops its TIN build
    options.max_vertices = env_.limits->max_vertices;
    options.max_faces = env_.limits->max_faces;
    absl::StatusOr<terrain::Dem> dem = terrain::Dem::ReadGeoTiffBytes(bytes_, file_name, options);
    if (ExceededLimit(dem.status())) return dem.status();  // names its flag on the way out
    if (const std::string option = InvalidOptionOf(dem.status()); !option.empty()) {
      return FieldError(absl::StrCat("metadata.dem.", option), dem.status().message());
    }
    if (!dem.ok()) return FieldError("chunk", dem.status().message());
    // What is stored must load again: the grid is rebuilt from the stored mesh then.
    if (absl::Status back = terrain::Dem::FromMesh(dem->mesh(), dem->info()).status(); !back.ok()) {
      return FieldError("chunk", absl::StrCat(file_name, ": ", back.message()));
    }
    return dem;
  }

  absl::Status BuildAndStore(v1::Mesh* response) {
    const ServiceLimits& limits = *env_.limits;
    ReadLimits read_limits;
    read_limits.max_vertices = limits.max_vertices;
    read_limits.max_faces = limits.max_faces;
    // A gzip upload inflates at most to the upload limit (checked while inflating).
    read_limits.max_decompressed_bytes = limits.max_upload_bytes;
    const std::string file_name = metadata_.file_name().empty()
                                      ? "upload"
                                      : std::string(metadata_.file_name().substr(0, kMaxEchoBytes));
    std::shared_ptr<const terrain::Dem> dem;
    if (dem_ ||
        (metadata_.format() == v1::MESH_FORMAT_UNSPECIFIED && terrain::LooksLikeTiff(bytes_))) {
      absl::StatusOr<terrain::Dem> read = ReadDem(file_name);
      if (!read.ok()) return read.status();
      dem = std::make_shared<const terrain::Dem>(*std::move(read));
    } else if (metadata_.has_dem()) {
      return FieldError("metadata.dem",
                        "DEM options are for a GeoTIFF upload, and this upload is not one");
    }
    // A DEM's mesh is its grid's (not copied); a mesh file's is read here.
    absl::StatusOr<MeshData> read =
        dem != nullptr
            ? MeshData()
            : ReadMeshFromBuffer(absl::string_view(bytes_), format_, file_name, read_limits);
    if (!read.ok()) {
      if (read.status().code() == absl::StatusCode::kResourceExhausted) return read.status();
      return FieldError("chunk", read.status().message());
    }
    const MeshData* data = dem != nullptr ? &dem->mesh() : &*read;
    if (data->vertex_count() > limits.max_vertices) {
      return ServerLimitError("max_vertices",
                              absl::StrCat("mesh has ", data->vertex_count(),
                                           " vertices, over --max_vertices=", limits.max_vertices));
    }
    if (data->face_count() > limits.max_faces) {
      return ServerLimitError("max_faces",
                              absl::StrCat("mesh has ", data->face_count(),
                                           " faces, over --max_faces=", limits.max_faces));
    }
    std::string id = ComputeMeshId(*data);
    if (!metadata_.expected_mesh_id().empty() && metadata_.expected_mesh_id() != id) {
      return FieldError(
          "metadata.expected_mesh_id",
          absl::StrCat(metadata_.expected_mesh_id(), " differs from the uploaded mesh's id ", id));
    }
    std::shared_ptr<StoredMesh> candidate;
    // A stored mesh that is this DEM's but was uploaded as a mesh file gains its map: build it.
    if (!env_.store->NeedsBuild(id, dem != nullptr)) {
      // Idempotent re-upload: no rebuild. (Insert adds the new alias to the stored mesh.)
      candidate = std::make_shared<StoredMesh>();
      candidate->id = id;
    } else {
      MeshBuildOptions build_options;
      build_options.strict = metadata_.strict();
      absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data, build_options);
      if (!mesh.ok()) {
        return FieldError("chunk", mesh.status().message());
      }
      if (cancel_.IsCancelled()) return absl::CancelledError("upload cancelled");
      candidate = MakeStoredMesh(id, *std::move(mesh), std::move(dem));
      candidate->upload_bytes = bytes_.size();
      candidate->pinned = metadata_.pin();
    }
    candidate->display_name = metadata_.display_name();
    const std::string canonical = env_.store->has_disk() && candidate->mesh != nullptr
                                      ? CanonicalMeshEncoding(*data)
                                      : std::string();
    absl::StatusOr<std::shared_ptr<const StoredMesh>> stored =
        env_.store->Insert(std::move(candidate), canonical, limits.max_names_per_mesh);
    if (!stored.ok()) return stored.status();
    MeshToProto(**stored, response);
    if (env_.descriptions != nullptr) env_.descriptions->SetMesh(context_, response->name());
    return absl::OkStatus();
  }

  ReactorEnv env_;
  grpc::CallbackServerContext* context_;
  grpc::ByteBuffer* response_;
  std::mutex mu_;  // guards the upload's state below (reads complete on several threads)
  grpc::ByteBuffer message_;
  uint64_t messages_ = 0;
  v1::CreateMeshMetadata metadata_;
  MeshFormat format_ = MeshFormat::kAuto;  // metadata_.format(), checked
  bool dem_ = false;                       // a GeoTIFF upload, by its format or file name
  bool have_metadata_ = false;
  std::string bytes_;
  CancelToken cancel_;
};

// ------------------------------------------------------------------------------------------
// The method table.

using Installer = grpc::internal::MethodHandler* (*)(const ReactorEnv* env, Lane lane);

template <typename Request, typename Response,
          absl::Status (*kRun)(const QueryEnv&, const Request&, Response*)>
grpc::internal::MethodHandler* Unary(const ReactorEnv* env, Lane lane) {
  return new grpc::internal::CallbackUnaryHandler<grpc::ByteBuffer, grpc::ByteBuffer>(
      [env, lane](grpc::CallbackServerContext* context, const grpc::ByteBuffer* request,
                  grpc::ByteBuffer* response) {
        return UnaryQueryReactor<Request, Response>::Start(*env, kRun, lane, context, request,
                                                           response);
      });
}

template <typename Request, typename Response,
          absl::StatusOr<MessageStream<Response>> (*kRun)(const QueryEnv&, const Request&)>
grpc::internal::MethodHandler* Stream(const ReactorEnv* env, Lane lane) {
  return new grpc::internal::CallbackServerStreamingHandler<grpc::ByteBuffer, grpc::ByteBuffer>(
      [env, lane](grpc::CallbackServerContext* context, const grpc::ByteBuffer* request) {
        return StreamQueryReactor<Request, Response>::Start(*env, kRun, lane, context, request);
      });
}

grpc::internal::MethodHandler* Upload(const ReactorEnv* env, Lane /*lane*/) {
  return new grpc::internal::CallbackClientStreamingHandler<grpc::ByteBuffer, grpc::ByteBuffer>(
      [env](grpc::CallbackServerContext* context, grpc::ByteBuffer* response) {
        return new CreateMeshReactor(*env, context, response);
      });
}

template <typename Request, typename Response,
          absl::Status (*kRun)(const QueryEnv&, const Request&, Response*)>
absl::Status RunUnarySerialized(const QueryEnv& env, absl::string_view bytes) {
  Request request;
  if (!request.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
    return absl::InvalidArgumentError("request does not parse");
  }
  Response response;
  return kRun(env, request, &response);
}

// A stream's pieces are drained (at most 100000, a bound for fuzzing) and dropped.
template <typename Request, typename Response,
          absl::StatusOr<MessageStream<Response>> (*kRun)(const QueryEnv&, const Request&)>
absl::Status RunStreamSerialized(const QueryEnv& env, absl::string_view bytes) {
  Request request;
  if (!request.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
    return absl::InvalidArgumentError("request does not parse");
  }
  absl::StatusOr<MessageStream<Response>> stream = kRun(env, request);
  if (!stream.ok()) return stream.status();
  if (stream->work) {
    if (absl::Status s = stream->work([] {}); !s.ok()) return s;
  }
  Response message;
  for (int i = 0; i < 100000; ++i) {
    const Produced produced = stream->next(&message);
    if (produced != Produced::kMessage) break;
    message.Clear();
  }
  return absl::OkStatus();
}

struct MethodRow {
  GeodexService::MethodInfo info;
  Installer install;
};

template <typename Request, typename Response,
          absl::Status (*kRun)(const QueryEnv&, const Request&, Response*)>
MethodRow UnaryRow(const char* name, Lane lane) {
  return {{name, lane, &RunUnarySerialized<Request, Response, kRun>},
          &Unary<Request, Response, kRun>};
}

template <typename Request, typename Response,
          absl::StatusOr<MessageStream<Response>> (*kRun)(const QueryEnv&, const Request&)>
MethodRow StreamRow(const char* name, Lane lane) {
  return {{name, lane, &RunStreamSerialized<Request, Response, kRun>},
          &Stream<Request, Response, kRun>};
}

// Append new methods at the end: the request fuzzer's seeds pick a method by its position among
// the rows it drives.
const std::vector<MethodRow>& MethodTable() {
  static const auto* table = new std::vector<MethodRow>{
      {{"CreateMesh", Lane::kSolve}, &Upload},
      UnaryRow<v1::GetMeshRequest, v1::Mesh, &RunGetMesh>("GetMesh", Lane::kInline),
      // A resident mesh: no solve; one on disk loads.
      StreamRow<v1::GetMeshGeometryRequest, v1::MeshGeometry, &RunGetMeshGeometry>(
          "GetMeshGeometry", Lane::kQuick),
      UnaryRow<v1::ListMeshesRequest, v1::ListMeshesResponse, &RunListMeshes>("ListMeshes",
                                                                              Lane::kInline),
      UnaryRow<v1::DeleteMeshRequest, v1::DeleteMeshResponse, &RunDeleteMesh>("DeleteMesh",
                                                                              Lane::kInline),
      UnaryRow<v1::DeriveMeshRequest, v1::Mesh, &RunDeriveMesh>("DeriveMesh", Lane::kSolve),
      StreamRow<v1::ComputeDistanceFieldRequest, v1::ComputeDistanceFieldResponse,
                &RunComputeDistanceField>("ComputeDistanceField", Lane::kQuick),
      UnaryRow<v1::FindShortestPathRequest, v1::FindShortestPathResponse, &RunFindShortestPath>(
          "FindShortestPath", Lane::kQuick),
      UnaryRow<v1::FindShortestPathsRequest, v1::FindShortestPathsResponse, &RunFindShortestPaths>(
          "FindShortestPaths", Lane::kSolve),
      // A repeated matrix is a cache hit.
      StreamRow<v1::ComputeDistanceMatrixRequest, v1::ComputeDistanceMatrixResponse,
                &RunComputeDistanceMatrix>("ComputeDistanceMatrix", Lane::kQuick),
      UnaryRow<v1::EstimateDistancesRequest, v1::EstimateDistancesResponse, &RunEstimateDistances>(
          "EstimateDistances", Lane::kQuick),
      UnaryRow<v1::LocatePointsRequest, v1::LocatePointsResponse, &RunLocatePoints>("LocatePoints",
                                                                                    Lane::kQuick),
      StreamRow<v1::ComputeIsolinesRequest, v1::ComputeIsolinesResponse, &RunComputeIsolines>(
          "ComputeIsolines", Lane::kQuick),
      StreamRow<v1::ComputeVoronoiRequest, v1::ComputeVoronoiResponse, &RunComputeVoronoi>(
          "ComputeVoronoi", Lane::kQuick),
      StreamRow<v1::ComputeDelaunayRequest, v1::ComputeDelaunayResponse, &RunComputeDelaunay>(
          "ComputeDelaunay", Lane::kQuick),
      // GEOS unions and GDAL writing: never on the quick lane.
      StreamRow<v1::ExportGisRequest, v1::ExportGisResponse, &RunExportGis>("ExportGis",
                                                                            Lane::kSolve),
  };
  return *table;
}

}  // namespace

const std::vector<GeodexService::MethodInfo>& GeodexService::Methods() {
  static const auto* methods = [] {
    auto* out = new std::vector<MethodInfo>;
    for (const MethodRow& row : MethodTable()) out->push_back(row.info);
    return out;
  }();
  return *methods;
}

GeodexService::GeodexService(MeshStore* store, ComputePool* pool, ComputePool* quick_pool,
                             FieldCache* cache, const ServiceLimits& limits,
                             TokenAuthenticator auth, CallDescriptions* descriptions)
    : store_(store), pool_(pool), limits_(limits), auth_(std::move(auth)) {
  env_ = ReactorEnv{store_, &limits_, pool_, quick_pool, cache, &counters_, &auth_, descriptions};
  // The generated base registered every method typed; each is replaced by its raw handler, by its
  // index in the service's descriptor (the order the base registered them in).
  const google::protobuf::ServiceDescriptor* service =
      google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(
          v1::Geodex::service_full_name());
  for (const MethodRow& row : MethodTable()) {
    const google::protobuf::MethodDescriptor* method = service->FindMethodByName(row.info.name);
    MarkMethodRawCallback(method->index(), row.install(&env_, row.info.lane));
  }
}

}  // namespace geodex::server
