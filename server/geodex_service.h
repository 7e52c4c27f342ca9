#pragma once

// geodex.v1.Geodex on gRPC's callback API. Reactors only move bytes and look things up; every
// parse, build and solve runs on the ComputePool, which Finish()es the call. A full pool answers
// RESOURCE_EXHAUSTED at once. Client cancellation and deadlines (OnCancel) cancel the engine's
// CancelToken; every reactor finishes, cancelled or not.

#include <cstdint>

#include "compute_pool.h"
#include "geodex/v1/geodex.grpc.pb.h"
#include "mesh_store.h"

namespace geodex::server {

// Request limits (all are geodexd flags; see geodexd_main.cc). Exceeding one answers
// RESOURCE_EXHAUSTED naming the flag.
struct ServiceLimits {
  uint64_t max_upload_bytes = uint64_t{1} << 30;  // --max_upload_bytes
  uint64_t max_vertices = 20'000'000;              // --max_vertices
  uint64_t max_faces = 40'000'000;                 // --max_faces
  uint32_t max_sources = 100'000;                  // --max_sources
  uint64_t max_output_values = 100'000'000;        // --max_output_values
  uint64_t max_windows = 0;                        // --max_windows (per solve; 0 = unlimited)
  uint32_t field_chunk_values = 131'072;           // values per streamed chunk (~1.5 MiB)
};

class GeodexService final : public v1::Geodex::CallbackService {
 public:
  // `store` and `pool` must outlive the service; the pool must also outlive the grpc::Server's
  // Shutdown (its tasks finish the calls).
  GeodexService(MeshStore* store, ComputePool* pool, const ServiceLimits& limits)
      : store_(store), pool_(pool), limits_(limits) {}

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

  MeshStore* store() const { return store_; }
  ComputePool* pool() const { return pool_; }
  const ServiceLimits& limits() const { return limits_; }

 private:
  MeshStore* store_;
  ComputePool* pool_;
  ServiceLimits limits_;
};

}  // namespace geodex::server
