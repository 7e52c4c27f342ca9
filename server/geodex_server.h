#pragma once

// Owns everything geodexd runs: the mesh store, the compute pool, the service and the grpc::Server
// with health checking (overall "" and "geodex.v1.Geodex") and reflection. Used by
// geodexd_main.cc and by the tests (in-process, on 127.0.0.1:0).

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "compute_pool.h"
#include "geodex_service.h"
#include "grpcpp/server.h"
#include "mesh_store.h"

namespace geodex::server {

struct ServerOptions {
  std::string listen = "127.0.0.1:50051";  // HOST:PORT; port 0 picks a free port
  std::string data_dir;                    // accepted; persistence arrives in part 2
  uint64_t mesh_budget_bytes = uint64_t{4} << 30;
  size_t pool_threads = 0;    // 0 = hardware concurrency
  size_t queue_capacity = 64;
  int max_receive_message_bytes = 4 << 20;  // per message; uploads are chunked below this
  ServiceLimits limits;
};

class GeodexServer {
 public:
  // Builds and starts the server. Errors: InvalidArgument/Unavailable when it cannot listen.
  static absl::StatusOr<std::unique_ptr<GeodexServer>> Start(const ServerOptions& options);
  ~GeodexServer();  // Shutdown(now) if not yet shut down

  // The port actually bound (useful with port 0).
  int port() const { return port_; }
  // Health NOT_SERVING, then grpc::Server::Shutdown(deadline): calls still running at the deadline
  // are cancelled (their workers stop at the next cancel-token poll and finish them).
  void Shutdown(absl::Time deadline);
  void Wait();

  MeshStore& store() { return *store_; }
  ComputePool& pool() { return *pool_; }
  grpc::Server& grpc_server() { return *server_; }

 private:
  GeodexServer() = default;
  // Declaration order = reverse destruction order: the server goes first, then the pool (joins
  // its workers), the service and the store.
  std::unique_ptr<MeshStore> store_;
  std::unique_ptr<GeodexService> service_;
  std::unique_ptr<ComputePool> pool_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;
  bool shut_down_ = false;
};

}  // namespace geodex::server
