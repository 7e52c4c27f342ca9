#pragma once

// The query methods of geodex.v1.Geodex as plain functions: request in, response (or a producer of
// stream messages) out, errors as absl::Status naming the request field or the server flag. They
// run on the compute pool (see query_reactors.h); nothing here knows about gRPC calls.

#include <atomic>
#include <cstdint>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "call_descriptions.h"
#include "compute_pool.h"
#include "geodex/cancel.h"
#include "geodex/v1/geodex.pb.h"
#include "mesh_store.h"
#include "message_stream.h"

namespace geodex::server {

struct ServiceLimits;
class FieldCache;

// Counters of the work done (read by the metrics).
struct ServiceCounters {
  std::atomic<uint64_t> solves{0};
  std::atomic<uint64_t> windows_processed{0};
  // Fields of hot path sources solved in the background (FieldPromoter), and offers dropped
  // because its queue was full.
  std::atomic<uint64_t> background_solves{0};
  std::atomic<uint64_t> background_dropped{0};
};

class FieldPromoter;

// What every query needs besides its request.
struct QueryEnv {
  MeshStore* store;
  const ServiceLimits* limits;
  const CancelToken* cancel;
  FieldCache* cache;
  ServiceCounters* counters;
  // Where a matrix's rows get helpers (queued behind other calls' work: a fair share); null: the
  // calling worker solves every row.
  ComputePool* pool = nullptr;
  // Where a path's hot source is offered for a background field solve; null: none.
  FieldPromoter* promoter = nullptr;
  // On the quick lane (query_reactors.h): answer only what needs no solve and no disk load;
  // anything else returns SolveLaneNeeded() and the call moves to the compute pool.
  bool quick = false;
};

// The sentinel a quick-lane query returns when it must solve (never sent to a client).
absl::Status SolveLaneNeeded();
bool IsSolveLaneNeeded(const absl::Status& status);

// Mesh resources (answered inline: map look-ups).
absl::Status RunGetMesh(const QueryEnv& env, const v1::GetMeshRequest& request, v1::Mesh* response);
// A stored mesh's positions and faces (loaded from disk if need be), streamed.
absl::StatusOr<MessageStream<v1::MeshGeometry>> RunGetMeshGeometry(
    const QueryEnv& env, const v1::GetMeshGeometryRequest& request);
absl::Status RunListMeshes(const QueryEnv& env, const v1::ListMeshesRequest& request,
                           v1::ListMeshesResponse* response);
absl::Status RunDeleteMesh(const QueryEnv& env, const v1::DeleteMeshRequest& request,
                           v1::DeleteMeshResponse* response);
// A mesh derived by a barrier, built and stored like an upload (on the pool).
absl::Status RunDeriveMesh(const QueryEnv& env, const v1::DeriveMeshRequest& request,
                           v1::Mesh* response);

// Unary queries.
absl::Status RunFindShortestPath(const QueryEnv& env, const v1::FindShortestPathRequest& request,
                                 v1::FindShortestPathResponse* response);
absl::Status RunFindShortestPaths(const QueryEnv& env, const v1::FindShortestPathsRequest& request,
                                  v1::FindShortestPathsResponse* response);
absl::Status RunEstimateDistances(const QueryEnv& env, const v1::EstimateDistancesRequest& request,
                                  v1::EstimateDistancesResponse* response);
absl::Status RunLocatePoints(const QueryEnv& env, const v1::LocatePointsRequest& request,
                             v1::LocatePointsResponse* response);

// Streamed queries: compute everything, then produce the messages.
absl::StatusOr<MessageStream<v1::ComputeDistanceFieldResponse>> RunComputeDistanceField(
    const QueryEnv& env, const v1::ComputeDistanceFieldRequest& request);
absl::StatusOr<MessageStream<v1::ComputeDistanceMatrixResponse>> RunComputeDistanceMatrix(
    const QueryEnv& env, const v1::ComputeDistanceMatrixRequest& request);
absl::StatusOr<MessageStream<v1::ComputeIsolinesResponse>> RunComputeIsolines(
    const QueryEnv& env, const v1::ComputeIsolinesRequest& request);
absl::StatusOr<MessageStream<v1::ComputeVoronoiResponse>> RunComputeVoronoi(
    const QueryEnv& env, const v1::ComputeVoronoiRequest& request);
absl::StatusOr<MessageStream<v1::ComputeDelaunayResponse>> RunComputeDelaunay(
    const QueryEnv& env, const v1::ComputeDelaunayRequest& request);
// A DEM mesh's GIS file (GeoJSON or GeoTIFF bytes, queries_gis.cc).
absl::StatusOr<MessageStream<v1::ExportGisResponse>> RunExportGis(
    const QueryEnv& env, const v1::ExportGisRequest& request);

// "meshes/{key}" looked up in the store: InvalidArgument for a malformed name, NotFound for an
// unknown one. `field` names the request field.
// On the quick lane a mesh that is not in memory is SolveLaneNeeded (loading it takes a while).
absl::StatusOr<std::shared_ptr<const StoredMesh>> LookupMesh(const QueryEnv& env,
                                                             const std::string& name,
                                                             const std::string& field);

}  // namespace geodex::server
