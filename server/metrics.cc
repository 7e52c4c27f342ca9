#include "metrics.h"

#include <algorithm>
#include <cctype>
#include <exception>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "absl/time/clock.h"
#include "google/protobuf/descriptor.h"
#include "google/protobuf/message.h"
#include "listen_address.h"
#include "prometheus/collectable.h"
#include "prometheus/counter.h"
#include "prometheus/exposer.h"
#include "prometheus/family.h"
#include "prometheus/histogram.h"
#include "prometheus/registry.h"
#include "spdlog/spdlog.h"

namespace geodex::server {

// Gauges and counters owned by other components, read at scrape time.
class GaugeCollector final : public prometheus::Collectable {
 public:
  explicit GaugeCollector(const MetricSources& sources) : sources_(sources) {}

  std::vector<prometheus::MetricFamily> Collect() const override {
    std::vector<prometheus::MetricFamily> out;
    auto add = [&](const char* name, const char* help, prometheus::MetricType type, double value) {
      prometheus::MetricFamily family;
      family.name = name;
      family.help = help;
      family.type = type;
      prometheus::ClientMetric metric;
      if (type == prometheus::MetricType::Counter) {
        metric.counter.value = value;
      } else {
        metric.gauge.value = value;
      }
      family.metric.push_back(std::move(metric));
      out.push_back(std::move(family));
    };
    using T = prometheus::MetricType;
    const ComputePool& pool = *sources_.pool;
    add("geodex_compute_queue_depth", "Calls waiting for a compute worker", T::Gauge,
        static_cast<double>(pool.queued()));
    add("geodex_compute_busy_workers", "Compute workers running a call", T::Gauge,
        static_cast<double>(pool.busy()));
    add("geodex_compute_workers", "Compute workers (--pool_threads)", T::Gauge,
        static_cast<double>(pool.threads()));
    add("geodex_compute_rejected_total", "Calls refused because the compute queue was full",
        T::Counter, static_cast<double>(pool.rejected()));
    const MeshStore& store = *sources_.store;
    add("geodex_mesh_store_bytes", "Memory of the meshes in RAM", T::Gauge,
        static_cast<double>(store.used_bytes()));
    add("geodex_mesh_store_budget_bytes", "Mesh memory budget (--mesh_budget_bytes)", T::Gauge,
        static_cast<double>(store.budget_bytes()));
    add("geodex_mesh_store_meshes", "Stored meshes (in RAM or on disk)", T::Gauge,
        static_cast<double>(store.size()));
    add("geodex_mesh_store_resident_meshes", "Meshes in RAM", T::Gauge,
        static_cast<double>(store.resident_count()));
    add("geodex_mesh_store_evictions_total", "Meshes evicted from RAM by the budget", T::Counter,
        static_cast<double>(store.evictions()));
    add("geodex_mesh_store_disk_loads_total", "Meshes loaded back from the data directory",
        T::Counter, static_cast<double>(store.disk_loads()));
    const FieldCache& cache = *sources_.cache;
    add("geodex_result_cache_bytes", "Memory of the cached distance fields and travel graphs",
        T::Gauge, static_cast<double>(cache.bytes()));
    add("geodex_result_cache_entries", "Cached distance fields and travel graphs", T::Gauge,
        static_cast<double>(cache.entries()));
    add("geodex_result_cache_hits_total", "Queries answered from a cached field", T::Counter,
        static_cast<double>(cache.hits()));
    add("geodex_result_cache_misses_total", "Cache look-ups that found no field", T::Counter,
        static_cast<double>(cache.misses()));
    add("geodex_travel_graph_hits_total",
        "Travel paths, point times and matrices that reused a cached travel graph", T::Counter,
        static_cast<double>(cache.graph_hits()));
    add("geodex_result_cache_declined_total",
        "Fields and graphs not kept: room would have evicted ones asked for more often", T::Counter,
        static_cast<double>(cache.declined()));
    add("geodex_travel_graph_misses_total", "Travel graph look-ups that built one", T::Counter,
        static_cast<double>(cache.graph_misses()));
    add("geodex_solves_total", "Geodesic solves run", T::Counter,
        static_cast<double>(sources_.counters->solves.load(std::memory_order_relaxed)));
    add("geodex_windows_processed_total", "ICH windows propagated by all solves", T::Counter,
        static_cast<double>(sources_.counters->windows_processed.load(std::memory_order_relaxed)));
    add("geodex_background_solves_total",
        "Fields of hot path sources solved in the background (off every caller's clock)",
        T::Counter,
        static_cast<double>(sources_.counters->background_solves.load(std::memory_order_relaxed)));
    add("geodex_background_dropped_total",
        "Background field offers dropped because the queue was full", T::Counter,
        static_cast<double>(sources_.counters->background_dropped.load(std::memory_order_relaxed)));
    return out;
  }

 private:
  MetricSources sources_;
};

namespace {

// The canonical name of a gRPC status code ("INVALID_ARGUMENT"); gRPC's codes are Abseil's.
std::string CodeName(int code) {
  const std::string name = absl::StatusCodeToString(static_cast<absl::StatusCode>(code));
  return name.empty() ? "UNKNOWN" : name;
}

// Client-supplied text in a log line: bounded, one token, printable (spdlog does not escape).
std::string Sanitize(absl::string_view text) {
  std::string out(text.substr(0, 128));
  for (char& c : out) {
    if (!std::isgraph(static_cast<unsigned char>(c)) || c == '"') c = '?';
  }
  return out.empty() ? "-" : out;
}

// One interceptor per call: notes what the request is about, then records and logs its outcome.
class RequestInterceptor final : public grpc::experimental::Interceptor {
 public:
  RequestInterceptor(grpc::experimental::ServerRpcInfo* info, ServerMetrics* metrics)
      : metrics_(metrics),
        call_(info->server_context()),
        method_(info->method() != nullptr ? info->method() : ""),
        start_(absl::Now()) {
    if (!method_.empty() && method_[0] == '/') method_.erase(0, 1);
    // geodex's own methods are raw (bytes): the service describes each call once it has parsed
    // the request (CallDescriptions), after the token check.
    ours_ = method_.rfind("geodex.v1.Geodex/", 0) == 0;
  }
  ~RequestInterceptor() override {
    if (ours_ && metrics_->descriptions() != nullptr) metrics_->descriptions()->Forget(call_);
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    using Hook = grpc::experimental::InterceptionHookPoints;
    if (methods->QueryInterceptionHookPoint(Hook::POST_RECV_INITIAL_METADATA)) {
      if (auto* metadata = methods->GetRecvInitialMetadata()) {
        auto it = metadata->find("x-request-id");
        if (it != metadata->end()) {
          request_id_ = Sanitize(absl::string_view(it->second.data(), it->second.size()));
        }
      }
    }
    if (ours_ && !metrics_->replica().empty() &&
        methods->QueryInterceptionHookPoint(Hook::PRE_SEND_INITIAL_METADATA)) {
      if (auto* metadata = methods->GetSendInitialMetadata()) {
        metadata->insert({"x-geodex-replica", metrics_->replica()});
      }
    }
    if (methods->QueryInterceptionHookPoint(Hook::PRE_SEND_STATUS)) {
      if (ours_ && metrics_->descriptions() != nullptr) {
        CallDescriptions::Entry entry = metrics_->descriptions()->Find(call_);
        mesh_ = std::move(entry.mesh);
        sources_ = entry.sources;
      }
      const grpc::Status status = methods->GetSendStatus();
      const double seconds = absl::ToDoubleSeconds(absl::Now() - start_);
      metrics_->RecordRequest(method_, status.error_code(), seconds);
      if (metrics_->log_requests()) {
        spdlog::info(
            "request method={} mesh={} sources={} duration_ms={:.3f} status={} request_id={}",
            method_, mesh_.empty() ? "-" : Sanitize(mesh_), sources_, seconds * 1e3,
            CodeName(status.error_code()), request_id_);
      }
    }
    methods->Proceed();
  }

 private:
  ServerMetrics* metrics_;
  const void* call_;
  std::string method_;
  absl::Time start_;
  bool ours_ = false;
  std::string mesh_;
  int sources_ = 0;
  std::string request_id_ = "-";
};

class RequestInterceptorFactory final
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit RequestInterceptorFactory(ServerMetrics* metrics) : metrics_(metrics) {}
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override {
    return new RequestInterceptor(info, metrics_);
  }

 private:
  ServerMetrics* metrics_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<ServerMetrics>> ServerMetrics::Start(const std::string& listen,
                                                                    const MetricSources& sources,
                                                                    bool log_requests,
                                                                    const std::string& replica) {
  std::unique_ptr<ServerMetrics> m(new ServerMetrics());
  m->log_requests_ = log_requests;
  m->replica_ = replica;
  m->descriptions_ = sources.descriptions;
  m->registry_ = std::make_shared<prometheus::Registry>();
  m->gauges_ = std::make_shared<GaugeCollector>(sources);
  m->requests_ = &prometheus::BuildCounter()
                      .Name("geodex_requests_total")
                      .Help("Calls finished, by gRPC method and status code")
                      .Register(*m->registry_);
  m->durations_ = &prometheus::BuildHistogram()
                       .Name("geodex_request_duration_seconds")
                       .Help("Call latency, by gRPC method")
                       .Register(*m->registry_);
  if (!listen.empty()) {
    try {
      m->exposer_ = std::make_unique<prometheus::Exposer>(listen);
    } catch (const std::exception& e) {
      if (AddressInUse(listen)) {
        return absl::UnavailableError(absl::StrCat(
            "--metrics_listen=", listen,
            ": address in use (another geodexd?); choose another port, 0 for a free one, or \"\" "
            "for no metrics endpoint"));
      }
      return absl::UnavailableError(
          absl::StrCat("--metrics_listen=", listen, ": cannot serve metrics (", e.what(), ")"));
    }
    m->exposer_->RegisterCollectable(m->registry_);
    m->exposer_->RegisterCollectable(m->gauges_);
    std::vector<int> ports = m->exposer_->GetListeningPorts();
    m->port_ = ports.empty() ? 0 : ports[0];
  }
  return m;
}

ServerMetrics::~ServerMetrics() = default;

void ServerMetrics::StopHttp() { exposer_.reset(); }

void ServerMetrics::RecordRequest(const std::string& method, int code, double seconds) {
  requests_->Add({{"method", method}, {"code", CodeName(code)}}).Increment();
  static const prometheus::Histogram::BucketBoundaries kBuckets = {
      0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60, 300};
  durations_->Add({{"method", method}}, kBuckets).Observe(seconds);
}

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>
ServerMetrics::InterceptorFactory() {
  return std::make_unique<RequestInterceptorFactory>(this);
}

}  // namespace geodex::server
