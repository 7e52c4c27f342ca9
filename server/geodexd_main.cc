// geodexd: the geodex gRPC server. `geodexd --help` lists every flag.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/time/clock.h"
#include "geodex/limits.h"
#include "geodex_server.h"
#include "spdlog/spdlog.h"

ABSL_FLAG(std::string, listen, "127.0.0.1:50051",
          "HOST:PORT to listen on (port 0 = any free port)");
ABSL_FLAG(std::string, data_dir, "",
          "Directory for persisted meshes (created if missing; empty = keep meshes in RAM only)");
ABSL_FLAG(bool, samples, true,
          "Offer the built-in sample meshes (terrain, torus, sphere) on a fresh data directory");
ABSL_FLAG(std::string, import_dir, "",
          "Import every mesh file of this server-side directory at start (alias = file name)");
ABSL_FLAG(uint64_t, mesh_budget_bytes, uint64_t{4} << 30,
          "RAM budget for preprocessed meshes; least-recently-used unpinned meshes are evicted");
ABSL_FLAG(uint64_t, result_cache_bytes, uint64_t{256} << 20,
          "Memory for finished distance fields reused by later queries with the same mesh, sources "
          "and options (0 = off)");
ABSL_FLAG(std::string, metrics_listen, "127.0.0.1:9464",
          "HOST:PORT of the Prometheus /metrics HTTP endpoint (empty = off)");
ABSL_FLAG(std::string, http_listen, "",
          "HOST:PORT of the HTTP/JSON API (docs/service.md, \"HTTP/JSON\"; empty = off)");
ABSL_FLAG(uint32_t, http_threads, 4, "HTTP requests served at once (each waits for its call)");
ABSL_FLAG(uint64_t, http_max_response_bytes, uint64_t{64} << 20,
          "Largest answer the HTTP port assembles from a stream (NDJSON answers are not bounded)");
ABSL_FLAG(std::vector<std::string>, http_allowed_hosts, {},
          "Host names the HTTP port answers besides localhost, 127.0.0.1 and [::1], when no "
          "bearer tokens are on (comma-separated; * = any: only behind a proxy that checks Host)");
ABSL_FLAG(std::string, http_grpc_target, "",
          "Where HTTP calls go: empty = this geodexd; HOST:PORT = a gateway's gRPC port, so HTTP "
          "calls are routed by mesh as gRPC calls are (deploy/gateway)");
ABSL_FLAG(std::string, http_cors_origin, "",
          "Origin allowed to call the HTTP port from a browser (CORS; * = any; empty = none)");
ABSL_FLAG(std::string, replica_name, "",
          "Name sent to clients as x-geodex-replica metadata (default: the host name)");
ABSL_FLAG(std::string, tls_cert, "",
          "PEM certificate (chain) of the server: serve TLS (with --tls_key)");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(std::string, auth_token_file, "",
          "File of bearer tokens, one per line: geodex.v1 calls need 'authorization: Bearer TOKEN' "
          "(health, reflection and metrics stay open)");
ABSL_FLAG(bool, allow_plaintext_tokens, false,
          "Allow --auth_token_file without TLS (only behind a TLS-terminating proxy: tokens then "
          "cross the proxy's link in plaintext)");
ABSL_FLAG(bool, background_solves, true,
          "Solve the whole field of a path source asked again in the background (one thread, "
          "lowest priority, bounded queue) so later paths from it are traces; never on a caller's "
          "clock");
ABSL_FLAG(bool, log_requests, true, "Log one line per call (method, mesh, sources, time, status)");
ABSL_FLAG(uint32_t, pool_threads, 0, "Compute worker threads (0 = one per hardware thread)");
ABSL_FLAG(uint32_t, quick_threads, 2,
          "Workers for calls that need no solve (metadata, locate, cached fields, traces and "
          "estimates from them), so that they never wait behind full solves (0 = no quick lane)");
ABSL_FLAG(uint32_t, queue_capacity, 64,
          "Queries that may wait for a worker; beyond that calls get RESOURCE_EXHAUSTED at once");
ABSL_FLAG(uint64_t, max_upload_bytes, uint64_t{1} << 30,
          "Largest mesh file accepted by CreateMesh");
ABSL_FLAG(uint64_t, max_vertices, 20'000'000, "Most vertices in an uploaded mesh");
ABSL_FLAG(uint64_t, max_faces, 40'000'000, "Most faces in an uploaded mesh");
ABSL_FLAG(uint64_t, max_dem_cells, 25'000'000,
          "Most cells (width x height) in an uploaded GeoTIFF DEM, checked before GDAL reads them");
ABSL_FLAG(
    uint32_t, max_names_per_mesh, 16,
    "Most names (display name and aliases from re-uploads under other names) one mesh may have");
ABSL_FLAG(uint32_t, max_sources, 100'000, "Most sources in one query");
ABSL_FLAG(
    uint32_t, max_targets, 50'000,
    "Most targets (matrix columns, EstimateDistances points, LocatePoints positions) per query");
ABSL_FLAG(uint32_t, max_levels, 1'000, "Most isoline levels per ComputeIsolines query");
ABSL_FLAG(uint64_t, max_output_values, 100'000'000,
          "Most values one query may return (field vertices, matrix cells)");
ABSL_FLAG(uint64_t, max_unary_response_bytes, 4 << 20,
          "Largest unary response (clients keep gRPC's default 4 MiB receive limit)");
ABSL_FLAG(uint32_t, stream_chunk_bytes, 1 << 20, "Approximate size of one streamed result message");
ABSL_FLAG(uint64_t, max_windows, geodex::kServerDefaultMaxWindows,
          "Work budget per solve: windows made, or a travel graph's links relaxed (32 a window); "
          "0 = unlimited");
ABSL_FLAG(uint64_t, max_steiner_points, geodex::kDefaultMaxSteinerPoints,
          "Most Steiner points of one travel-cost solve (SolverOptions.travel; about 32 bytes "
          "each, refused before they are allocated; 0 = unlimited)");
ABSL_FLAG(int32_t, max_receive_message_bytes, 4 << 20,
          "Largest single request message (uploads are chunked below this)");
ABSL_FLAG(double, shutdown_grace_seconds, 10,
          "On SIGTERM/SIGINT, time given to running calls before they are cancelled");

namespace {

int g_signal_pipe[2] = {-1, -1};

void OnSignal(int sig) {
  const unsigned char byte = static_cast<unsigned char>(sig);
  [[maybe_unused]] ssize_t n = write(g_signal_pipe[1], &byte, 1);
}

}  // namespace

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage(
      "geodexd --listen HOST:PORT --data-dir DIR [flags]: the geodex gRPC server "
      "(geodex.v1.Geodex, grpc.health.v1.Health, server reflection)");
  // --version prints CMake's project version (absl's default says which build type it was).
  absl::FlagsUsageConfig usage;
  usage.version_string = [] { return std::string("geodexd " GEODEX_VERSION "\n"); };
  absl::SetFlagsUsageConfig(usage);
  // Accept --data-dir as well as --data_dir, for every flag (absl flags use underscores; the
  // command-line contract in docs/service.md uses dashes).
  std::vector<std::string> args(argv, argv + argc);
  std::vector<char*> fixed;
  for (std::string& a : args) {
    if (a.rfind("--", 0) == 0) {
      const size_t name_end = std::min(a.find('='), a.size());
      for (size_t i = 2; i < name_end; ++i) {
        if (a[i] == '-') a[i] = '_';
      }
    }
    fixed.push_back(a.data());
  }
  absl::ParseCommandLine(static_cast<int>(fixed.size()), fixed.data());

  // SIGTERM/SIGINT may land on any thread (gRPC starts threads before main): the handler only
  // writes the signal number to a pipe, which the main thread reads.
  if (pipe(g_signal_pipe) != 0) {
    spdlog::error("pipe: {}", std::strerror(errno));
    return 1;
  }
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);

  geodex::server::ServerOptions options;
  options.listen = absl::GetFlag(FLAGS_listen);
  options.data_dir = absl::GetFlag(FLAGS_data_dir);
  options.samples = absl::GetFlag(FLAGS_samples);
  options.import_dir = absl::GetFlag(FLAGS_import_dir);
  options.mesh_budget_bytes = absl::GetFlag(FLAGS_mesh_budget_bytes);
  options.result_cache_bytes = absl::GetFlag(FLAGS_result_cache_bytes);
  options.metrics_listen = absl::GetFlag(FLAGS_metrics_listen);
  options.log_requests = absl::GetFlag(FLAGS_log_requests);
  options.background_solves = absl::GetFlag(FLAGS_background_solves);
  options.replica_name = absl::GetFlag(FLAGS_replica_name);
  options.tls_cert_file = absl::GetFlag(FLAGS_tls_cert);
  options.tls_key_file = absl::GetFlag(FLAGS_tls_key);
  options.auth_token_file = absl::GetFlag(FLAGS_auth_token_file);
  options.allow_plaintext_tokens = absl::GetFlag(FLAGS_allow_plaintext_tokens);
  options.http.listen = absl::GetFlag(FLAGS_http_listen);
  options.http.threads = absl::GetFlag(FLAGS_http_threads);
  options.http.max_response_bytes = absl::GetFlag(FLAGS_http_max_response_bytes);
  options.http.allowed_hosts = absl::GetFlag(FLAGS_http_allowed_hosts);
  options.http.cors_origin = absl::GetFlag(FLAGS_http_cors_origin);
  options.http.grpc_target = absl::GetFlag(FLAGS_http_grpc_target);
  if (options.replica_name.empty()) {
    char host[256] = {};
    if (gethostname(host, sizeof host - 1) == 0) options.replica_name = host;
  }
  options.pool_threads = absl::GetFlag(FLAGS_pool_threads);
  options.quick_threads = absl::GetFlag(FLAGS_quick_threads);
  options.queue_capacity = absl::GetFlag(FLAGS_queue_capacity);
  options.max_receive_message_bytes = absl::GetFlag(FLAGS_max_receive_message_bytes);
  options.limits.max_upload_bytes = absl::GetFlag(FLAGS_max_upload_bytes);
  options.limits.max_vertices = absl::GetFlag(FLAGS_max_vertices);
  options.limits.max_faces = absl::GetFlag(FLAGS_max_faces);
  options.limits.max_dem_cells = absl::GetFlag(FLAGS_max_dem_cells);
  options.limits.max_sources = absl::GetFlag(FLAGS_max_sources);
  options.limits.max_names_per_mesh = absl::GetFlag(FLAGS_max_names_per_mesh);
  options.limits.max_targets = absl::GetFlag(FLAGS_max_targets);
  options.limits.max_levels = absl::GetFlag(FLAGS_max_levels);
  options.limits.max_output_values = absl::GetFlag(FLAGS_max_output_values);
  options.limits.max_unary_response_bytes = absl::GetFlag(FLAGS_max_unary_response_bytes);
  options.limits.stream_chunk_bytes = absl::GetFlag(FLAGS_stream_chunk_bytes);
  options.limits.max_windows = absl::GetFlag(FLAGS_max_windows);
  options.limits.max_steiner_points = absl::GetFlag(FLAGS_max_steiner_points);
  const double grace = absl::GetFlag(FLAGS_shutdown_grace_seconds);
  if (!(grace >= 0 && grace <= 24 * 3600)) {
    spdlog::error("--shutdown_grace_seconds={}: must be between 0 and 86400", grace);
    return 1;
  }
  auto server = geodex::server::GeodexServer::Start(options);
  if (!server.ok()) {
    spdlog::error("{}", std::string(server.status().message()));
    return 1;
  }
  const geodex::server::StartupReport& report = (*server)->startup_report();
  if (!options.data_dir.empty()) {
    spdlog::info("data dir {}: {} meshes indexed", options.data_dir, report.indexed);
  }
  for (const auto& skipped : report.skipped) {
    spdlog::warn("skipped {}: {}", skipped.path, skipped.reason);
  }
  for (const auto& path : report.removed_temporaries) {
    spdlog::warn("removed {} (a write interrupted by a crash)", path);
  }
  for (const auto& line : report.samples) spdlog::info("sample {}", line);
  for (const auto& line : report.imported) spdlog::info("imported {}", line);
  for (const auto& line : report.import_errors) spdlog::warn("import failed: {}", line);
  // The effective configuration, one line.
  spdlog::info(
      "config replica={} listen={} data_dir={} samples={} mesh_budget_bytes={} "
      "result_cache_bytes={} "
      "pool_threads={} quick_threads={} "
      "queue_capacity={} max_upload_bytes={} max_vertices={} max_faces={} max_dem_cells={} "
      "max_sources={} "
      "max_targets={} max_levels={} max_output_values={} max_windows={} max_steiner_points={} "
      "max_unary_response_bytes={} stream_chunk_bytes={} shutdown_grace_seconds={}",
      options.replica_name, options.listen, options.data_dir.empty() ? "(none)" : options.data_dir,
      options.samples, options.mesh_budget_bytes, options.result_cache_bytes,
      (*server)->pool().threads(), options.quick_threads, options.queue_capacity,
      options.limits.max_upload_bytes, options.limits.max_vertices, options.limits.max_faces,
      options.limits.max_dem_cells, options.limits.max_sources, options.limits.max_targets,
      options.limits.max_levels, options.limits.max_output_values, options.limits.max_windows,
      options.limits.max_steiner_points, options.limits.max_unary_response_bytes,
      options.limits.stream_chunk_bytes, absl::GetFlag(FLAGS_shutdown_grace_seconds));
  if ((*server)->metrics().port() != 0) {
    const std::string& listen = options.metrics_listen;
    spdlog::info("metrics on http://{}:{}/metrics", listen.substr(0, listen.rfind(':')),
                 (*server)->metrics().port());
  }
  if ((*server)->http_port() != 0) {
    const std::string& listen = options.http.listen;
    spdlog::info("HTTP/JSON API on http://{}:{}/v1/meshes", listen.substr(0, listen.rfind(':')),
                 (*server)->http_port());
  }
  if ((*server)->authenticated() && !(*server)->tls()) {
    spdlog::warn(
        "--allow_plaintext_tokens: bearer tokens arrive without TLS; only safe behind a "
        "TLS-terminating proxy on a trusted link");
  }
  spdlog::info("security: tls={} bearer_tokens={}", (*server)->tls(), (*server)->authenticated());
  spdlog::info("geodexd listening on port {} ({} workers, queue {}, mesh budget {} bytes)",
               (*server)->port(), (*server)->pool().threads(), options.queue_capacity,
               options.mesh_budget_bytes);

  unsigned char sig = 0;
  while (read(g_signal_pipe[0], &sig, 1) < 0 && errno == EINTR) {
  }
  spdlog::info("signal {}: shutting down (grace {} s)", static_cast<int>(sig),
               absl::GetFlag(FLAGS_shutdown_grace_seconds));
  (*server)->Shutdown(absl::Now() + absl::Seconds(absl::GetFlag(FLAGS_shutdown_grace_seconds)));
  spdlog::info("geodexd stopped");
  return 0;
}
