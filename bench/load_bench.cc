// geodex_load_bench: a geodexd process under sustained load and overload, bounded in time.
//
//   geodex_load_bench [--geodexd PATH] [--mesh FILE]... [--seconds S] [--workers W] [--queue Q]
//                     [--overload F] [--mesh_budget_mib M] [--cache_mib C] [--seed K]
//
// Starts the geodexd binary as a child on 127.0.0.1 (ports it picks, a fresh data directory, no
// samples) with W compute workers, a queue of Q and the given budgets; uploads the meshes (default:
// armadillo from ../shared/meshes when present, and the six meshes of tests/data); then drives the
// query mix of query_mix.h for S seconds in each of three phases:
//   sustained  W clients             (every call finds a free worker)
//   full       W + Q clients         (workers and queue full, nothing refused)
//   overload   F x (W + Q) clients   (RESOURCE_EXHAUSTED at once is the designed answer)
// Each client has its own connection; a separate connection probes grpc.health.v1 every 20 ms. A
// sampler reads the child's VmRSS (/proc/PID/status) every 50 ms and its metrics endpoint (mesh
// store and result cache bytes) every 250 ms. The default mesh budget is 60% of the uploaded
// meshes' memory (at least 1.2 x the largest), so meshes are evicted and reloaded from disk
// during the run.
//
// Reports, per phase: answered queries/s, p50/p99 latency (overall and per kind), every gRPC
// status by name, health p50/p99/max and failures, peak RSS, store and cache bytes. Then checks:
// no status other than OK and RESOURCE_EXHAUSTED, no health failure, health p99 < 50 ms, store and
// cache within their budgets, and a clean exit of geodexd on SIGTERM. Exit 0 only if all hold.
// Only the child it started is signalled. docs/reliability.md records the figures.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "geodex/mesh_io.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/channel_arguments.h"
#include "query_mix.h"
#include "testkit/geodexd_child.h"

namespace geodex::bench {
namespace {

namespace fs = std::filesystem;

// A channel of its own (a distinct argument keeps gRPC from sharing the connection).
std::shared_ptr<grpc::Channel> OwnChannel(int port, const std::string& tag) {
  grpc::ChannelArguments args;
  args.SetString("geodex.bench.connection", tag);
  args.SetMaxReceiveMessageSize(64 << 20);
  return grpc::CreateCustomChannel(absl::StrCat("127.0.0.1:", port),
                                   grpc::InsecureChannelCredentials(), args);
}

uint64_t StatusKb(pid_t pid, const char* key) {
  std::ifstream in(absl::StrCat("/proc/", pid, "/status"));
  std::string line;
  const std::string prefix = absl::StrCat(key, ":");
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) == 0) return std::stoull(line.substr(prefix.size()));
  }
  return 0;
}

// GET /metrics on 127.0.0.1:port; the body, or "" on any error.
std::string ScrapeMetrics(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "";
  timeval timeout{2, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string text;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
    const std::string request = "GET /metrics HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
    if (::send(fd, request.data(), request.size(), 0) == static_cast<ssize_t>(request.size())) {
      char buffer[1 << 14];
      for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) text.append(buffer, n);
    }
  }
  ::close(fd);
  return text;
}

// The value of an unlabelled metric in a Prometheus text exposition, or -1.
double MetricValue(const std::string& text, const std::string& name) {
  const std::regex line("(^|\n)" + name + " ([0-9.e+]+)");
  std::smatch m;
  return std::regex_search(text, m, line) ? std::stod(m[2]) : -1;
}

// geodexd on DIR/data with no samples, both ports picked by it, plus `flags`.
class Child : public testing_support::GeodexdChild {
 public:
  Child(const fs::path& dir, const std::string& binary, std::vector<std::string> flags)
      : GeodexdChild(Args(dir, binary, std::move(flags)), dir / "geodexd.log") {}

 private:
  static std::vector<std::string> Args(const fs::path& dir, const std::string& binary,
                                       std::vector<std::string> flags) {
    std::vector<std::string> args = {
        binary,        "--listen",   "127.0.0.1:0",           "--metrics_listen",
        "127.0.0.1:0", "--data-dir", (dir / "data").string(), "--samples=false"};
    args.insert(args.end(), flags.begin(), flags.end());
    return args;
  }
};

struct PhaseReport {
  std::string name;
  int clients = 0;
  double seconds = 0;
  MixResult mix;
  std::vector<double> health_ms;
  int health_failures = 0;
  uint64_t peak_rss_kb = 0;
  double peak_store_bytes = 0, peak_cache_bytes = 0;
};

PhaseReport RunPhase(const std::string& name, Child& child, const std::vector<MixMesh>& meshes,
                     int clients, double seconds, uint32_t seed) {
  PhaseReport report;
  report.name = name;
  report.clients = clients;
  std::atomic<bool> stop{false};
  std::vector<std::future<MixResult>> futures;
  const auto start = Clock::now();
  for (int c = 0; c < clients; ++c) {
    futures.push_back(std::async(std::launch::async, RunMixClient,
                                 OwnChannel(child.port(), absl::StrCat(name, c)), std::cref(meshes),
                                 seed + c, std::cref(stop)));
  }
  std::thread sampler([&] {
    for (int tick = 0; !stop.load(); ++tick) {
      report.peak_rss_kb = std::max(report.peak_rss_kb, StatusKb(child.pid(), "VmRSS"));
      if (tick % 5 == 0) {
        const std::string text = ScrapeMetrics(child.metrics_port());
        report.peak_store_bytes =
            std::max(report.peak_store_bytes, MetricValue(text, "geodex_mesh_store_bytes"));
        report.peak_cache_bytes =
            std::max(report.peak_cache_bytes, MetricValue(text, "geodex_result_cache_bytes"));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  grpc::GenericStub health(OwnChannel(child.port(), "health-" + name));
  while (Ms(Clock::now() - start) < seconds * 1e3) {
    const auto t0 = Clock::now();
    report.health_failures += !HealthCheck(health).ok();
    report.health_ms.push_back(Ms(Clock::now() - t0));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  stop = true;
  for (auto& f : futures) report.mix.Merge(f.get());
  sampler.join();
  report.seconds = Ms(Clock::now() - start) / 1e3;
  return report;
}

void Print(const PhaseReport& r) {
  const int ok = r.mix.statuses.count("OK") ? r.mix.statuses.at("OK") : 0;
  std::string statuses;
  for (const auto& [k, v] : r.mix.statuses) absl::StrAppend(&statuses, k, "=", v, " ");
  std::printf("\n%s: %d clients for %.1f s\n", r.name.c_str(), r.clients, r.seconds);
  std::printf("  answered %d (%.1f/s), all calls p50 %.1f ms p99 %.1f ms; statuses %s\n", ok,
              ok / r.seconds, Percentile(r.mix.latencies_ms, 0.5),
              Percentile(r.mix.latencies_ms, 0.99), statuses.c_str());
  std::printf("  answered by kind:");
  for (const auto& [kind, ms] : r.mix.kind_ms) {
    std::printf("  %s n=%zu p50=%.1f p99=%.1f", kind.c_str(), ms.size(), Percentile(ms, 0.5),
                Percentile(ms, 0.99));
  }
  std::printf("\n  health: %zu checks, p50 %.2f ms, p99 %.2f ms, max %.2f ms, failures %d\n",
              r.health_ms.size(), Percentile(r.health_ms, 0.5), Percentile(r.health_ms, 0.99),
              r.health_ms.empty() ? 0.0 : *std::max_element(r.health_ms.begin(), r.health_ms.end()),
              r.health_failures);
  std::printf("  geodexd peak RSS %.0f MiB; mesh store peak %.1f MiB; result cache peak %.1f MiB\n",
              r.peak_rss_kb / 1024.0, r.peak_store_bytes / 1048576.0,
              r.peak_cache_bytes / 1048576.0);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int Main(int argc, char** argv) {
  std::string geodexd = GEODEXD_BINARY;
  std::vector<std::string> mesh_paths;
  double seconds = 20, overload = 4;
  int workers = 2, queue = 4;
  double mesh_budget_mib = 0, cache_mib = 64;
  uint32_t seed = 1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--geodexd")
      geodexd = value;
    else if (flag == "--mesh")
      mesh_paths.push_back(value);
    else if (flag == "--seconds")
      seconds = std::stod(value);
    else if (flag == "--workers")
      workers = std::stoi(value);
    else if (flag == "--queue")
      queue = std::stoi(value);
    else if (flag == "--overload")
      overload = std::stod(value);
    else if (flag == "--mesh_budget_mib")
      mesh_budget_mib = std::stod(value);
    else if (flag == "--cache_mib")
      cache_mib = std::stod(value);
    else if (flag == "--seed")
      seed = static_cast<uint32_t>(std::stoul(value));
    else {
      std::fprintf(stderr, "unknown flag %s (see the comment at the top of load_bench.cc)\n",
                   flag.c_str());
      return 2;
    }
  }
  if (mesh_paths.empty()) {
    const std::string source = GEODEX_SOURCE_DIR;
    if (fs::exists(source + "/../shared/meshes/armadillo.off")) {
      mesh_paths.push_back(source + "/../shared/meshes/armadillo.off");
    }
    for (const char* name :
         {"fertility", "bump-domain", "kitten", "bunny-npm", "three-peaks", "knight"}) {
      mesh_paths.push_back(absl::StrCat(source, "/tests/data/", name, ".off"));
    }
  }

  // The meshes as the clients see them (vertex and face counts, positions for LocatePoints).
  std::vector<MixMesh> meshes;
  std::vector<std::string> files;
  for (size_t i = 0; i < mesh_paths.size(); ++i) {
    absl::StatusOr<MeshData> data = ReadMeshFile(mesh_paths[i]);
    if (!data.ok()) {
      std::fprintf(stderr, "%s\n", std::string(data.status().message()).c_str());
      return 1;
    }
    meshes.push_back({absl::StrCat("meshes/load", i), static_cast<uint32_t>(data->vertex_count()),
                      static_cast<uint32_t>(data->face_count()), data->positions});
    files.push_back(ReadFile(mesh_paths[i]));
  }

  const fs::path dir = fs::temp_directory_path() / absl::StrCat("geodex-load-", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  // First a child with no budget pressure, only to learn the meshes' memory; then the real one.
  uint64_t mesh_memory = 0, largest_mesh = 0;
  {
    Child probe(dir / "probe", geodexd, {"--pool_threads", "1"});
    if (probe.port() == 0) {
      std::fprintf(stderr, "geodexd did not start:\n%s\n", probe.Log().c_str());
      return 1;
    }
    auto stub = v1::Geodex::NewStub(OwnChannel(probe.port(), "probe"));
    for (size_t i = 0; i < files.size(); ++i) {
      v1::Mesh created;
      grpc::Status s = Upload(*stub, files[i], fs::path(mesh_paths[i]).filename(),
                              absl::StrCat("probe", i), &created);
      if (!s.ok()) {
        std::fprintf(stderr, "upload of %s: %s\n", mesh_paths[i].c_str(),
                     s.error_message().c_str());
        return 1;
      }
      mesh_memory += created.memory_bytes();
      largest_mesh = std::max<uint64_t>(largest_mesh, created.memory_bytes());
    }
    probe.Terminate(30);
  }
  if (mesh_budget_mib <= 0) {
    mesh_budget_mib = std::max(0.6 * mesh_memory, 1.2 * largest_mesh) / 1048576.0;
  }
  const uint64_t mesh_budget = static_cast<uint64_t>(mesh_budget_mib * 1048576.0);
  const uint64_t cache_budget = static_cast<uint64_t>(cache_mib * 1048576.0);

  Child child(dir, geodexd,
              {"--pool_threads", std::to_string(workers), "--queue_capacity", std::to_string(queue),
               "--mesh_budget_bytes", std::to_string(mesh_budget), "--result_cache_bytes",
               std::to_string(cache_budget)});
  if (child.port() == 0 || child.metrics_port() == 0) {
    std::fprintf(stderr, "geodexd did not start:\n%s\n", child.Log().c_str());
    return 1;
  }
  const uint64_t idle_rss_kb = StatusKb(child.pid(), "VmRSS");
  {
    auto stub = v1::Geodex::NewStub(OwnChannel(child.port(), "upload"));
    for (size_t i = 0; i < files.size(); ++i) {
      grpc::Status s =
          Upload(*stub, files[i], fs::path(mesh_paths[i]).filename(), absl::StrCat("load", i));
      if (!s.ok()) {
        std::fprintf(stderr, "upload of %s: %s\n", mesh_paths[i].c_str(),
                     s.error_message().c_str());
        return 1;
      }
    }
  }
  std::printf(
      "geodexd pid %d: %d workers, queue %d, mesh budget %.1f MiB (meshes need %.1f MiB), "
      "result cache %.0f MiB; idle RSS %.0f MiB; hardware threads %u\n",
      child.pid(), workers, queue, mesh_budget / 1048576.0, mesh_memory / 1048576.0, cache_mib,
      idle_rss_kb / 1024.0, std::thread::hardware_concurrency());
  std::printf("meshes:");
  for (size_t i = 0; i < meshes.size(); ++i) {
    std::printf(" %s (%u faces)", fs::path(mesh_paths[i]).filename().c_str(), meshes[i].faces);
  }
  std::printf(
      "\nquery mix: 40%% A* paths, 20%% fields, 20%% point distances x16, 10%% locate x64, "
      "10%% isolines; a random mesh per query\n");

  const int overload_clients = static_cast<int>(overload * (workers + queue) + 0.5);
  std::vector<PhaseReport> phases;
  phases.push_back(RunPhase("sustained", child, meshes, workers, seconds, seed * 1000));
  phases.push_back(RunPhase("full", child, meshes, workers + queue, seconds, seed * 2000));
  phases.push_back(RunPhase("overload", child, meshes, overload_clients, seconds, seed * 3000));
  for (const PhaseReport& r : phases) Print(r);

  const std::string metrics = ScrapeMetrics(child.metrics_port());
  const uint64_t hwm_kb = StatusKb(child.pid(), "VmHWM");
  double peak_store = 0, peak_cache = 0;
  int other_errors = 0, health_failures = 0, refused_outside_overload = 0;
  double worst_health_p99 = 0;
  for (const PhaseReport& r : phases) {
    peak_store = std::max(peak_store, r.peak_store_bytes);
    peak_cache = std::max(peak_cache, r.peak_cache_bytes);
    for (const auto& [k, v] : r.mix.statuses) {
      if (k != "OK" && k != "RESOURCE_EXHAUSTED") other_errors += v;
      if (k == "RESOURCE_EXHAUSTED" && r.name != "overload") refused_outside_overload += v;
    }
    health_failures += r.health_failures;
    worst_health_p99 = std::max(worst_health_p99, Percentile(r.health_ms, 0.99));
  }
  std::printf(
      "\nmeshes evicted from RAM %.0f, loaded back from disk %.0f; cache hits %.0f, "
      "misses %.0f\n",
      MetricValue(metrics, "geodex_mesh_store_evictions_total"),
      MetricValue(metrics, "geodex_mesh_store_disk_loads_total"),
      MetricValue(metrics, "geodex_result_cache_hits_total"),
      MetricValue(metrics, "geodex_result_cache_misses_total"));
  std::printf(
      "geodexd peak RSS (VmHWM) %.0f MiB = idle %.0f + mesh budget %.1f + cache budget %.0f "
      "+ %.0f MiB of solver working memory and gRPC buffers for %d workers\n",
      hwm_kb / 1024.0, idle_rss_kb / 1024.0, mesh_budget / 1048576.0, cache_mib,
      (static_cast<double>(hwm_kb) * 1024 - static_cast<double>(idle_rss_kb) * 1024 -
       static_cast<double>(mesh_budget) - static_cast<double>(cache_budget)) /
          1048576.0,
      workers);
  const int exit_code = child.Terminate(60);

  bool pass = true;
  auto check = [&](bool ok, const std::string& what) {
    std::printf("  %s  %s\n", ok ? "PASS" : "FAIL", what.c_str());
    pass = pass && ok;
  };
  std::printf("\nchecks:\n");
  check(other_errors == 0,
        absl::StrCat("statuses other than OK and RESOURCE_EXHAUSTED: ", other_errors));
  check(refused_outside_overload == 0,
        absl::StrCat("RESOURCE_EXHAUSTED before the overload phase: ", refused_outside_overload));
  check(health_failures == 0, absl::StrCat("failed health checks: ", health_failures));
  check(worst_health_p99 < 50,
        absl::StrFormat("worst health p99 %.2f ms < 50 ms", worst_health_p99));
  check(peak_store <= static_cast<double>(mesh_budget),
        absl::StrFormat("mesh store peak %.1f MiB <= budget %.1f MiB", peak_store / 1048576.0,
                        mesh_budget / 1048576.0));
  check(peak_cache <= static_cast<double>(cache_budget),
        absl::StrFormat("result cache peak %.1f MiB <= budget %.0f MiB", peak_cache / 1048576.0,
                        cache_mib));
  check(exit_code == 0, absl::StrCat("geodexd exit status after SIGTERM: ", exit_code));
  if (pass)
    fs::remove_all(dir);
  else
    std::printf("geodexd log kept in %s\n", dir.c_str());
  return pass ? 0 : 1;
}

}  // namespace
}  // namespace geodex::bench

int main(int argc, char** argv) { return geodex::bench::Main(argc, argv); }
