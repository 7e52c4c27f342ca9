#pragma once

// Prometheus metrics of geodexd (prometheus-cpp, served over HTTP on their own port) and the
// per-request observer: a gRPC server interceptor that, for every call of every service, counts it
// by method and status, records its latency and writes one structured log line (and tags geodex.v1
// responses with the replica's name).
//
// Metrics (all prefixed geodex_):
//   requests_total{method,code}            calls finished, by gRPC method and status code
//   request_duration_seconds{method}       latency histogram
//   compute_queue_depth, compute_busy_workers, compute_workers, compute_rejected_total
//   mesh_store_bytes, mesh_store_budget_bytes, mesh_store_meshes, mesh_store_resident_meshes,
//   mesh_store_evictions_total, mesh_store_disk_loads_total
//   result_cache_bytes, result_cache_entries, result_cache_hits_total, result_cache_misses_total
//   travel_graph_hits_total, travel_graph_misses_total (travel graphs, in the result cache)
//   solves_total, windows_processed_total
// The gauges are read from the pool, store and cache at scrape time.

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "compute_pool.h"
#include "field_cache.h"
#include "grpcpp/support/server_interceptor.h"
#include "mesh_store.h"
#include "queries.h"

namespace prometheus {
class Exposer;
class Registry;
template <typename T>
class Family;
class Counter;
class Histogram;
}  // namespace prometheus

namespace geodex::server {

// What the metrics read at scrape time (all must outlive the ServerMetrics).
struct MetricSources {
  const ComputePool* pool;
  const MeshStore* store;
  const FieldCache* cache;
  const ServiceCounters* counters;
  CallDescriptions* descriptions;  // what each call is about, for its log line (may be null)
};

class ServerMetrics {
 public:
  // Without `listen` ("" = no HTTP endpoint) the metrics are still counted (and logged).
  // `replica` (may be empty) is sent to clients as `x-geodex-replica` initial metadata on every
  // geodex.v1 call, so that routing through a gateway is observable.
  static absl::StatusOr<std::unique_ptr<ServerMetrics>> Start(const std::string& listen,
                                                              const MetricSources& sources,
                                                              bool log_requests,
                                                              const std::string& replica = "");
  ~ServerMetrics();

  // The HTTP port serving /metrics (0 when not listening).
  int port() const { return port_; }
  // Stops serving /metrics (before the components it reads are destroyed).
  void StopHttp();

  // Called once per finished call by the interceptor.
  void RecordRequest(const std::string& method, int code, double seconds);
  bool log_requests() const { return log_requests_; }
  const std::string& replica() const { return replica_; }
  CallDescriptions* descriptions() const { return descriptions_; }

  // The interceptor factory to install on the grpc::ServerBuilder.
  std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> InterceptorFactory();

 private:
  ServerMetrics() = default;
  std::shared_ptr<prometheus::Registry> registry_;
  std::shared_ptr<class GaugeCollector> gauges_;
  std::unique_ptr<prometheus::Exposer> exposer_;
  prometheus::Family<prometheus::Counter>* requests_ = nullptr;
  prometheus::Family<prometheus::Histogram>* durations_ = nullptr;
  int port_ = 0;
  bool log_requests_ = true;
  std::string replica_;
  CallDescriptions* descriptions_ = nullptr;
};

}  // namespace geodex::server
