#pragma once

// geodex.v1.Geodex on gRPC's callback API. Reactors only move bytes and look things up; every
// parse, build and solve runs on the ComputePool, which Finish()es the call. A full pool answers
// RESOURCE_EXHAUSTED at once. Client cancellation and deadlines (OnCancel) cancel the engine's
// CancelToken; every reactor finishes, cancelled or not.

#include <cstdint>

#include "auth.h"
#include "compute_pool.h"
#include "field_cache.h"
#include "geodex/v1/geodex.grpc.pb.h"
#include "mesh_store.h"
#include "query_reactors.h"
#include "service_limits.h"

namespace geodex::server {

class GeodexService final : public v1::Geodex::CallbackService {
 public:
  // `store` and `pool` must outlive the service; the pool must also outlive the grpc::Server's
  // Shutdown (its tasks finish the calls).
  // `cache` (the result cache) must outlive the service too.
  GeodexService(MeshStore* store, ComputePool* pool, FieldCache* cache, const ServiceLimits& limits,
                TokenAuthenticator auth = TokenAuthenticator({}))
      : store_(store), pool_(pool), cache_(cache), limits_(limits), auth_(std::move(auth)) {}

  grpc::ServerReadReactor<v1::CreateMeshRequest>* CreateMesh(grpc::CallbackServerContext* context,
                                                             v1::Mesh* response) override;
  grpc::ServerUnaryReactor* GetMesh(grpc::CallbackServerContext* context,
                                    const v1::GetMeshRequest* request,
                                    v1::Mesh* response) override;
  grpc::ServerUnaryReactor* ListMeshes(grpc::CallbackServerContext* context,
                                       const v1::ListMeshesRequest* request,
                                       v1::ListMeshesResponse* response) override;
  grpc::ServerUnaryReactor* DeleteMesh(grpc::CallbackServerContext* context,
                                       const v1::DeleteMeshRequest* request,
                                       v1::DeleteMeshResponse* response) override;
  grpc::ServerWriteReactor<v1::ComputeDistanceFieldResponse>* ComputeDistanceField(
      grpc::CallbackServerContext* context,
      const v1::ComputeDistanceFieldRequest* request) override;
  grpc::ServerUnaryReactor* FindShortestPath(grpc::CallbackServerContext* context,
                                             const v1::FindShortestPathRequest* request,
                                             v1::FindShortestPathResponse* response) override;
  grpc::ServerWriteReactor<v1::ComputeDistanceMatrixResponse>* ComputeDistanceMatrix(
      grpc::CallbackServerContext* context,
      const v1::ComputeDistanceMatrixRequest* request) override;
  grpc::ServerUnaryReactor* EstimateDistances(grpc::CallbackServerContext* context,
                                              const v1::EstimateDistancesRequest* request,
                                              v1::EstimateDistancesResponse* response) override;
  grpc::ServerUnaryReactor* LocatePoints(grpc::CallbackServerContext* context,
                                         const v1::LocatePointsRequest* request,
                                         v1::LocatePointsResponse* response) override;
  grpc::ServerWriteReactor<v1::ComputeIsolinesResponse>* ComputeIsolines(
      grpc::CallbackServerContext* context, const v1::ComputeIsolinesRequest* request) override;
  grpc::ServerWriteReactor<v1::ComputeVoronoiResponse>* ComputeVoronoi(
      grpc::CallbackServerContext* context, const v1::ComputeVoronoiRequest* request) override;
  grpc::ServerWriteReactor<v1::ComputeDelaunayResponse>* ComputeDelaunay(
      grpc::CallbackServerContext* context, const v1::ComputeDelaunayRequest* request) override;

  MeshStore* store() const { return store_; }
  ComputePool* pool() const { return pool_; }
  const ServiceLimits& limits() const { return limits_; }
  const ServiceCounters& counters() const { return counters_; }

 private:
  ReactorEnv env() { return ReactorEnv{store_, &limits_, pool_, cache_, &counters_}; }

  MeshStore* store_;
  ComputePool* pool_;
  FieldCache* cache_;
  ServiceLimits limits_;
  TokenAuthenticator auth_;
  ServiceCounters counters_;
};

}  // namespace geodex::server
