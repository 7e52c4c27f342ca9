// geodex_service_bench: geodexd under load, measured side by side with core in one run.
//
//   geodex_service_bench [--mesh FILE] [--seconds S] [--threads N] [--seed K] [--sections 1234]
//
// An in-process geodexd on 127.0.0.1:0 (N compute workers) is given the mesh (default: armadillo,
// 86k faces, from ../shared/meshes), then:
//   1. overhead: a full distance field through the service (result cache off) against
//      ComputeDistanceField called directly on the same mesh, interleaved, median of 7 each;
//   2. a query mix (A* paths 40%, distance fields 20%, point distances 20%, locate 10%,
//      isolines 10%; random vertices and points) from 1, 2 and 4 concurrent clients for S seconds
//      each: throughput, p50/p99 latency, status counts;
//   3. health checks while every worker is busy with full fields: p50/p99/max;
//   4. planner matrices (issue 19), result cache off: 64 x 64 symmetric matrices between seeded
//      random vertices spread over the mesh and between waypoints within a ball of 10% of the
//      bounding-box diagonal, on 1 and on N workers, each against one full field through the same
//      server (median of 3): matrix / field, the speed-up over one worker, and when the first
//      streamed row arrived.
// Load, overload and memory against a separate geodexd process: geodex_load_bench (load_bench.cc).
// Results go to stdout as a table (docs/performance.md records them).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "geodex/geodesic_solver.h"
#include "geodex/mesh_io.h"
#include "geodex/triangle_mesh.h"
#include "geodex/v1/geodex.grpc.pb.h"
#include "geodex_server.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/byte_buffer.h"
#include "query_mix.h"

namespace geodex::server {
namespace {

using bench::Clock;
using bench::In;
using bench::Ms;
using bench::Percentile;

// Peak resident set of this process (VmHWM), in KiB.
grpc::Status Field(v1::Geodex::Stub& stub, uint32_t source, size_t* values) {
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh("meshes/bench");
  request.add_sources()->set_vertex(source);
  grpc::ClientContext context;
  context.set_deadline(In(600));
  auto reader = stub.ComputeDistanceField(&context, request);
  v1::ComputeDistanceFieldResponse response;
  size_t n = 0;
  while (reader->Read(&response)) n += response.distances_f64_size();
  if (values != nullptr) *values = n;
  return reader->Finish();
}

// An in-process geodexd on 127.0.0.1:0 with `workers` compute workers and the mesh uploaded as
// "meshes/bench". Null server on failure.
struct BenchServer {
  std::unique_ptr<GeodexServer> server;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::Geodex::Stub> stub;
};

BenchServer StartBenchServer(int workers, bool result_cache, const std::string& bytes,
                             const std::string& mesh_path) {
  BenchServer out;
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.pool_threads = workers;
  if (!result_cache) options.result_cache_bytes = 0;
  auto server = GeodexServer::Start(options);
  if (!server.ok()) return out;
  out.channel = grpc::CreateChannel(absl::StrCat("127.0.0.1:", (*server)->port()),
                                    grpc::InsecureChannelCredentials());
  out.stub = v1::Geodex::NewStub(out.channel);
  if (!bench::Upload(*out.stub, bytes, mesh_path, "bench").ok()) {
    (*server)->Shutdown(absl::Now() + absl::Seconds(30));
    return out;
  }
  out.server = *std::move(server);
  return out;
}

// One 64 x 64 matrix through the service: wall ms, and ms until the first message with values.
grpc::Status Matrix(v1::Geodex::Stub& stub, const std::vector<uint32_t>& points, double* total_ms,
                    double* first_row_ms) {
  v1::ComputeDistanceMatrixRequest request;
  request.set_mesh("meshes/bench");
  for (uint32_t v : points) {
    request.add_sources()->set_vertex(v);
    request.add_targets()->set_vertex(v);
  }
  grpc::ClientContext context;
  context.set_deadline(In(600));
  const auto t0 = Clock::now();
  auto reader = stub.ComputeDistanceMatrix(&context, request);
  v1::ComputeDistanceMatrixResponse response;
  size_t values = 0;
  *first_row_ms = -1;
  while (reader->Read(&response)) {
    if (response.values_f64_size() > 0 && *first_row_ms < 0) *first_row_ms = Ms(Clock::now() - t0);
    values += response.values_f64_size();
  }
  *total_ms = Ms(Clock::now() - t0);
  grpc::Status status = reader->Finish();
  if (status.ok() && values != points.size() * points.size()) {
    return grpc::Status(grpc::StatusCode::INTERNAL, "short matrix");
  }
  return status;
}

// Section 4: planner matrices on 1 and on `threads` workers, against one full field each time.
int MatrixSection(const TriangleMesh& mesh, const std::string& bytes, const std::string& mesh_path,
                  int threads, uint32_t seed) {
  const uint32_t n = mesh.file_vertex_count();
  std::mt19937 rng(seed * 2010);
  std::vector<uint32_t> spread, local, near;
  for (int i = 0; i < 64; ++i) spread.push_back(rng() % n);
  const auto lo = mesh.BoundsMin(), hi = mesh.BoundsMax();
  auto dist = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
  };
  const double radius = 0.05 * dist(lo, hi);  // a region of 10% of the diameter
  const uint32_t centre = rng() % n;
  for (uint32_t v = 0; v < n; ++v) {
    if (dist(mesh.Position(v), mesh.Position(centre)) < radius) near.push_back(v);
  }
  std::shuffle(near.begin(), near.end(), rng);
  local.assign(near.begin(), near.begin() + std::min<size_t>(64, near.size()));
  std::printf(
      "\n4. planner matrices, result cache off (median of 3; field: one full field "
      "through the same server)\n");
  std::printf(
      "   matrix          workers   field ms   matrix ms   / field   speed-up   first row ms\n");
  std::map<std::string, double> one_worker;
  for (int workers : {1, threads}) {
    BenchServer bench_server = StartBenchServer(workers, /*result_cache=*/false, bytes, mesh_path);
    if (bench_server.server == nullptr) return 1;
    auto& stub = bench_server.stub;
    for (const auto& [label, points] :
         {std::pair<std::string, const std::vector<uint32_t>*>{"64 x 64 spread", &spread},
          {"64 x 64 local", &local}}) {
      std::vector<double> fields, matrices, firsts;
      for (int run = 0; run < 3; ++run) {
        auto t0 = Clock::now();
        if (!Field(*stub, static_cast<uint32_t>((run * 7919u + 1) % n), nullptr).ok()) return 1;
        fields.push_back(Ms(Clock::now() - t0));
        double total = 0, first = 0;
        grpc::Status status = Matrix(*stub, *points, &total, &first);
        if (!status.ok()) {
          std::fprintf(stderr, "matrix: %s\n", status.error_message().c_str());
          return 1;
        }
        matrices.push_back(total);
        firsts.push_back(first);
      }
      const double f = Percentile(fields, 0.5), m = Percentile(matrices, 0.5);
      if (workers == 1) one_worker[label] = m;
      std::printf("   %-15s %7d   %8.1f   %9.1f   %7.2f   %8.2f   %12.1f\n", label.c_str(), workers,
                  f, m, m / f, one_worker[label] / m, Percentile(firsts, 0.5));
    }
    bench_server.server->Shutdown(absl::Now() + absl::Seconds(30));
    if (threads == 1) break;
  }
  return 0;
}

int Main(int argc, char** argv) {
  std::string mesh_path = std::string(GEODEX_SOURCE_DIR) + "/../shared/meshes/armadillo.off";
  double seconds = 10;
  int threads = 2;
  uint32_t seed = 1;
  std::string sections = "1234";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--mesh") {
      mesh_path = value;
    } else if (flag == "--seconds") {
      seconds = std::stod(value);
    } else if (flag == "--threads") {
      threads = std::stoi(value);
    } else if (flag == "--seed") {
      seed = static_cast<uint32_t>(std::stoul(value));
    } else if (flag == "--sections") {
      sections = value;
    } else {
      std::fprintf(stderr, "unknown flag %s\n", flag.c_str());
      return 2;
    }
  }
  std::string bytes;
  {
    std::FILE* f = std::fopen(mesh_path.c_str(), "rb");
    if (f == nullptr) {
      std::fprintf(stderr, "cannot open %s\n", mesh_path.c_str());
      return 1;
    }
    char buffer[1 << 16];
    for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) bytes.append(buffer, n);
    std::fclose(f);
  }
  absl::StatusOr<MeshData> data = ReadMeshFile(mesh_path);
  if (!data.ok()) {
    std::fprintf(stderr, "%s\n", std::string(data.status().message()).c_str());
    return 1;
  }
  const TriangleMesh mesh = *TriangleMesh::Build(*data);
  std::printf("mesh %s: %u vertices, %u faces; %d compute workers, hardware threads %u\n",
              mesh_path.c_str(), mesh.file_vertex_count(), mesh.face_count(), threads,
              std::thread::hardware_concurrency());

  auto want = [&](char section) { return sections.find(section) != std::string::npos; };
  // 1. Overhead of the service for a full field, result cache off.
  if (want('1')) {
    BenchServer bench_server = StartBenchServer(threads, /*result_cache=*/false, bytes, mesh_path);
    if (bench_server.server == nullptr) return 1;
    auto& stub = bench_server.stub;
    std::vector<double> direct, service;
    for (int run = 0; run < 7; ++run) {
      const uint32_t source = static_cast<uint32_t>((run * 7919u) % mesh.file_vertex_count());
      auto t0 = Clock::now();
      absl::StatusOr<DistanceField> field =
          ComputeDistanceField(mesh, {SurfacePoint::AtVertex(source)});
      direct.push_back(Ms(Clock::now() - t0));
      t0 = Clock::now();
      size_t values = 0;
      grpc::Status status = Field(*stub, source, &values);
      service.push_back(Ms(Clock::now() - t0));
      if (!status.ok() || values != field->distance.size()) return 1;
    }
    const double d = Percentile(direct, 0.5), s = Percentile(service, 0.5);
    std::printf("\n1. full field, result cache off (median of 7, same sources, interleaved)\n");
    std::printf("   core ComputeDistanceField  %8.1f ms\n", d);
    std::printf("   geodexd ComputeDistanceField %8.1f ms   overhead %+.1f%%\n", s,
                100.0 * (s - d) / d);
    bench_server.server->Shutdown(absl::Now() + absl::Seconds(30));
  }

  if (want('4') && MatrixSection(mesh, bytes, mesh_path, threads, seed) != 0) return 1;
  if (!want('2') && !want('3')) return 0;

  // 2. Query mix from 1, 2 and 4 clients.
  BenchServer bench_server = StartBenchServer(threads, /*result_cache=*/true, bytes, mesh_path);
  if (bench_server.server == nullptr) return 1;
  GeodexServer* server = bench_server.server.get();
  std::shared_ptr<grpc::Channel> channel = bench_server.channel;
  const std::vector<bench::MixMesh> mix_meshes = {
      {"meshes/bench", mesh.file_vertex_count(), mesh.face_count(), data->positions}};
  std::printf(
      "\n2. query mix for %.0f s per row (40%% A* paths, 20%% fields, 20%% point "
      "distances x16, 10%% locate x64, 10%% isolines)\n",
      seconds);
  std::printf("   clients  queries  queries/s   p50 ms   p99 ms   statuses\n");
  for (int clients : {1, 2, 4}) {
    if (!want('2')) break;
    std::atomic<bool> stop{false};
    std::vector<std::future<bench::MixResult>> futures;
    const auto start = Clock::now();
    for (int c = 0; c < clients; ++c) {
      futures.push_back(std::async(std::launch::async, bench::RunMixClient, channel,
                                   std::cref(mix_meshes), seed * 100 + c, std::cref(stop)));
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    stop = true;
    bench::MixResult all;
    for (auto& f : futures) all.Merge(f.get());
    const double elapsed = Ms(Clock::now() - start) / 1e3;
    std::string statuses;
    for (const auto& [k, v] : all.statuses) absl::StrAppend(&statuses, k, "=", v, " ");
    std::printf("   %7d  %7d  %9.1f  %7.1f  %7.1f   %s\n", clients, all.queries,
                all.queries / elapsed, Percentile(all.latencies_ms, 0.5),
                Percentile(all.latencies_ms, 0.99), statuses.c_str());
  }

  // 3. Health while every worker is busy with full fields (distinct sources: no cache hits).
  if (want('3')) {
    std::atomic<bool> stop{false};
    std::vector<std::thread> load;
    for (int c = 0; c < threads + 1; ++c) {
      load.emplace_back([&, c] {
        auto stub = v1::Geodex::NewStub(channel);
        for (uint32_t i = 0; !stop.load(); ++i) {
          Field(*stub, static_cast<uint32_t>((c * 100003u + i * 7919u) % mesh.file_vertex_count()),
                nullptr);
        }
      });
    }
    while (server->pool().busy() < static_cast<size_t>(threads)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    grpc::GenericStub generic(channel);
    std::vector<double> health;
    int busy_samples = 0, failures = 0;
    for (int i = 0; i < 300; ++i) {
      busy_samples += server->pool().busy() == static_cast<size_t>(threads);
      const auto t0 = Clock::now();
      failures += !bench::HealthCheck(generic).ok();
      health.push_back(Ms(Clock::now() - t0));
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    stop = true;
    for (auto& t : load) t.join();
    std::printf(
        "\n3. health checks while all %d workers compute full fields (300 checks, all busy "
        "at %d of them)\n",
        threads, busy_samples);
    std::printf("   p50 %.2f ms   p99 %.2f ms   max %.2f ms   failures %d\n",
                Percentile(health, 0.5), Percentile(health, 0.99),
                *std::max_element(health.begin(), health.end()), failures);
  }
  server->Shutdown(absl::Now() + absl::Seconds(60));

  return 0;
}

}  // namespace
}  // namespace geodex::server

int main(int argc, char** argv) { return geodex::server::Main(argc, argv); }
