#pragma once

// Owns everything geodexd runs: the mesh store, the compute pool, the service and the grpc::Server
// with health checking (overall "" and "geodex.v1.Geodex") and reflection. Used by
// geodexd_main.cc and by the tests (in-process, on 127.0.0.1:0).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "compute_pool.h"
#include "field_promoter.h"
#include "geodex_service.h"
#include "grpcpp/server.h"
#include "health_service.h"
#include "http_edge.h"
#include "mesh_store.h"
#include "metrics.h"

namespace geodex::server {

// What happened at start, for geodexd to log.
struct StartupReport {
  size_t indexed = 0;                            // meshes found in the data directory
  std::vector<MeshDisk::Skipped> skipped;        // corrupt/truncated files (left in place)
  std::vector<std::string> removed_temporaries;  // writes interrupted by a crash
  std::vector<std::string> samples;              // built-in samples added
  std::vector<std::string> imported;             // "file -> meshes/id"
  std::vector<std::string> import_errors;        // "file: reason"
};

struct ServerOptions {
  std::string listen = "127.0.0.1:50051";  // HOST:PORT; port 0 picks a free port
  std::string data_dir;                    // persisted meshes (mesh_disk.h); empty = RAM only
  bool samples = false;    // offer the built-in samples on a fresh data directory (or RAM only);
                           // geodexd turns this on by default (--samples)
  std::string import_dir;  // meshes to import at start (server-side files; never request paths)
  uint64_t mesh_budget_bytes = uint64_t{4} << 30;
  size_t pool_threads = 0;  // 0 = hardware concurrency
  // Workers of the quick lane: calls that need no solve (locate, cached fields and traces) never
  // wait behind full solves (query_reactors.h). 0 = no quick lane (the behaviour before it).
  size_t quick_threads = 2;
  size_t queue_capacity = 64;
  int max_receive_message_bytes = 4 << 20;            // per message; uploads are chunked below this
  uint64_t result_cache_bytes = uint64_t{256} << 20;  // finished fields kept for reuse; 0 = off
  // A path source asked again gets its whole field solved in the background (FieldPromoter: one
  // thread, lowest priority, never on a caller's clock), so later paths from it are traces.
  bool background_solves = true;
  std::string metrics_listen;  // HOST:PORT of the Prometheus /metrics endpoint; "" = none
  bool log_requests = false;   // one spdlog line per call (geodexd: on)
  std::string replica_name;    // sent as x-geodex-replica on every geodex.v1 call; "" = none
  // TLS: PEM files of the server certificate (chain) and its private key; both or neither.
  std::string tls_cert_file, tls_key_file;
  // Bearer tokens (auth.h): a file with one token per line; "" = no authentication. Refused
  // without TLS unless allow_plaintext_tokens (a TLS-terminating proxy in front).
  std::string auth_token_file;
  bool allow_plaintext_tokens = false;
  ServiceLimits limits;
  // The HTTP/JSON port (http_edge.h); off unless http.listen is given. Its JSON body limit is
  // max_receive_message_bytes, and it serves TLS and checks tokens as the gRPC port does.
  HttpEdgeOptions http;
};

// Parses nothing: builds `data` and stores it under `alias` (may be empty) unless a mesh with the
// same id is stored already. Returns the mesh id.
absl::StatusOr<std::string> AddMesh(MeshStore& store, const MeshData& data,
                                    const std::string& alias, uint64_t file_bytes);

// Checks the settings before anything starts: InvalidArgument naming the flag and its allowed
// range for a value that cannot work (no thread pool of 100,000 threads, no zero-byte messages,
// no budget of zero). GeodexServer::Start calls it first.
absl::Status ValidateServerOptions(const ServerOptions& options);
inline constexpr size_t kMaxPoolThreads = 1024;
inline constexpr size_t kMaxQuickThreads = 64;
inline constexpr size_t kMaxQueueCapacity = 1'000'000;
inline constexpr uint64_t kMaxStreamChunkBytes = 3 << 20;

// A whole (small) file, e.g. a PEM certificate; InvalidArgument naming `flag` when
// unreadable/empty.
absl::StatusOr<std::string> ReadSmallFile(const std::string& path, const std::string& flag);

class GeodexServer {
 public:
  // Builds and starts the server. Errors: InvalidArgument for unreadable TLS or token files,
  // Unavailable when it cannot listen.
  static absl::StatusOr<std::unique_ptr<GeodexServer>> Start(const ServerOptions& options);
  ~GeodexServer();  // Shutdown(now) if not yet shut down

  const StartupReport& startup_report() const { return report_; }
  bool tls() const { return tls_; }
  bool authenticated() const { return authenticated_; }
  // The port actually bound (useful with port 0).
  int port() const { return port_; }
  // The HTTP/JSON port bound (0 when off).
  int http_port() const { return http_ != nullptr ? http_->port() : 0; }
  // Health NOT_SERVING, then grpc::Server::Shutdown(deadline): calls still running at the deadline
  // are cancelled (their workers stop at the next cancel-token poll and finish them).
  void Shutdown(absl::Time deadline);
  void Wait();

  MeshStore& store() { return *store_; }
  ComputePool& pool() { return *pool_; }
  ComputePool* quick_pool() { return quick_pool_.get(); }  // null with quick_threads = 0
  FieldCache& cache() { return *cache_; }
  ServerMetrics& metrics() { return *metrics_; }
  GeodexService& service() { return *service_; }
  grpc::Server& grpc_server() { return *server_; }

 private:
  GeodexServer() = default;
  void ImportDirectory(const std::string& dir);
  // Declaration order = reverse destruction order: the server goes first, then the pool (joins
  // its workers), the service and the store.
  std::unique_ptr<MeshStore> store_;
  std::unique_ptr<FieldCache> cache_;
  CallDescriptions descriptions_;           // written by the service, read by the interceptor
  std::unique_ptr<ServerMetrics> metrics_;  // the interceptor records into it: outlives server_
  std::unique_ptr<GeodexService> service_;
  std::unique_ptr<HealthService> health_;
  std::unique_ptr<ComputePool> pool_;
  std::unique_ptr<ComputePool> quick_pool_;
  std::unique_ptr<FieldPromoter> promoter_;  // stopped once the calls are done
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<HttpEdge> http_;  // calls server_ in-process: stopped before it goes
  int port_ = 0;
  bool tls_ = false, authenticated_ = false;
  StartupReport report_;
  bool shut_down_ = false;
};

}  // namespace geodex::server
