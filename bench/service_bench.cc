// geodex_service_bench: geodexd under load, measured side by side with core in one run.
//
//   geodex_service_bench [--mesh FILE] [--seconds S] [--threads N] [--seed K]
//
// An in-process geodexd on 127.0.0.1:0 (N compute workers) is given the mesh (default: armadillo,
// 86k faces, from ../shared/meshes), then:
//   1. overhead: a full distance field through the service (result cache off) against
//      ComputeDistanceField called directly on the same mesh, interleaved, median of 7 each;
//   2. a query mix (A* paths 40%, distance fields 20%, point distances 20%, locate 10%,
//      isolines 10%; random vertices and points) from 1, 2 and 4 concurrent clients for S seconds
//      each: throughput, p50/p99 latency, status counts;
//   3. health checks while every worker is busy with full fields: p50/p99/max;
//   4. overload: 8 clients against the workers and a queue of 2 for S seconds, with health probes
//      alongside: answered, refused (RESOURCE_EXHAUSTED, by design), other errors (must be 0),
//      health latency, peak RSS against the mesh and cache budgets.
// Results go to stdout as a table (docs/performance.md records them).

#include <algorithm>
#include <atomic>
#include <chrono>
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

namespace geodex::server {
namespace {

using Clock = std::chrono::steady_clock;

// Peak resident set of this process (VmHWM), in KiB.
uint64_t PeakRssKb() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return 0;
  char line[256];
  uint64_t kb = 0;
  while (std::fgets(line, sizeof line, f)) {
    if (std::sscanf(line, "VmHWM: %lu kB", &kb) == 1) break;
  }
  std::fclose(f);
  return kb;
}

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5));
  return v[k];
}

std::chrono::system_clock::time_point In(double seconds) {
  return std::chrono::system_clock::now() +
         std::chrono::microseconds(static_cast<int64_t>(seconds * 1e6));
}

grpc::Status Upload(v1::Geodex::Stub& stub, const std::string& bytes, const std::string& name,
                    const std::string& alias) {
  grpc::ClientContext context;
  context.set_deadline(In(600));
  v1::Mesh mesh;
  auto writer = stub.CreateMesh(&context, &mesh);
  v1::CreateMeshRequest request;
  request.mutable_metadata()->set_file_name(name);
  request.mutable_metadata()->set_display_name(alias);
  writer->Write(request);
  for (size_t offset = 0; offset < bytes.size(); offset += 1 << 20) {
    request.Clear();
    request.set_chunk(bytes.substr(offset, 1 << 20));
    if (!writer->Write(request)) break;
  }
  writer->WritesDone();
  return writer->Finish();
}

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

grpc::Status HealthCheck(grpc::GenericStub& stub) {
  grpc::Slice slice(std::string{});
  grpc::ByteBuffer in(&slice, 1), out;
  grpc::ClientContext context;
  context.set_deadline(In(30));
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &in, &out,
                 [&](grpc::Status s) { done.set_value(s); });
  return done.get_future().get();
}

struct MixResult {
  std::vector<double> latencies_ms;
  std::map<std::string, int> statuses;
  int queries = 0;
};

// One client running the query mix until `stop`.
MixResult RunClient(const std::shared_ptr<grpc::Channel>& channel, const TriangleMesh& mesh,
                    const std::vector<double>& positions, uint32_t seed,
                    const std::atomic<bool>& stop) {
  auto stub = v1::Geodex::NewStub(channel);
  std::mt19937 rng(seed);
  const uint32_t n = static_cast<uint32_t>(mesh.file_vertex_count());
  const uint32_t faces = static_cast<uint32_t>(mesh.face_count());
  std::uniform_int_distribution<uint32_t> vertex(0, n - 1), face(0, faces - 1), kind(0, 9);
  std::uniform_real_distribution<double> unit(0.05, 0.9);
  auto face_point = [&](v1::SurfacePoint* p) {
    double a = unit(rng), b = unit(rng) * (1 - a);
    auto* f = p->mutable_face();
    f->set_face(face(rng));
    f->set_b0(a);
    f->set_b1(b);
    f->set_b2(1 - a - b);
  };
  MixResult result;
  while (!stop.load()) {
    const uint32_t k = kind(rng);
    const auto start = Clock::now();
    grpc::Status status;
    grpc::ClientContext context;
    context.set_deadline(In(600));
    if (k < 4) {  // A* path between random vertices
      v1::FindShortestPathRequest request;
      request.set_mesh("meshes/bench");
      request.mutable_from()->set_vertex(vertex(rng));
      request.mutable_to()->set_vertex(vertex(rng));
      v1::FindShortestPathResponse response;
      status = stub->FindShortestPath(&context, request, &response);
    } else if (k < 6) {  // full field
      v1::ComputeDistanceFieldRequest request;
      request.set_mesh("meshes/bench");
      request.add_sources()->set_vertex(vertex(rng));
      auto reader = stub->ComputeDistanceField(&context, request);
      v1::ComputeDistanceFieldResponse response;
      while (reader->Read(&response)) {
      }
      status = reader->Finish();
    } else if (k < 8) {  // estimate + exact at 16 face points
      v1::EstimateDistancesRequest request;
      request.set_mesh("meshes/bench");
      request.add_sources()->set_vertex(vertex(rng));
      for (int i = 0; i < 16; ++i) face_point(request.add_points());
      request.set_mode(v1::POINT_DISTANCE_MODE_BOTH);
      v1::EstimateDistancesResponse response;
      status = stub->EstimateDistances(&context, request, &response);
    } else if (k < 9) {  // locate 64 positions near vertices
      v1::LocatePointsRequest request;
      request.set_mesh("meshes/bench");
      for (int i = 0; i < 64; ++i) {
        const double* p = &positions[3 * size_t{vertex(rng)}];  // file coordinates
        auto* q = request.add_positions();
        q->set_x(p[0] + 0.01);
        q->set_y(p[1] - 0.01);
        q->set_z(p[2]);
      }
      v1::LocatePointsResponse response;
      status = stub->LocatePoints(&context, request, &response);
    } else {  // isolines
      v1::ComputeIsolinesRequest request;
      request.set_mesh("meshes/bench");
      request.add_sources()->set_vertex(vertex(rng));
      request.set_count(8);
      auto reader = stub->ComputeIsolines(&context, request);
      v1::ComputeIsolinesResponse response;
      while (reader->Read(&response)) {
      }
      status = reader->Finish();
    }
    result.latencies_ms.push_back(Ms(Clock::now() - start));
    ++result.statuses[status.ok() ? "OK" : absl::StrCat("code ", status.error_code())];
    ++result.queries;
  }
  return result;
}

int Main(int argc, char** argv) {
  std::string mesh_path = std::string(GEODEX_SOURCE_DIR) + "/../shared/meshes/armadillo.off";
  double seconds = 10;
  int threads = 2;
  uint32_t seed = 1;
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

  // 1. Overhead of the service for a full field, result cache off.
  {
    ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.pool_threads = threads;
    options.result_cache_bytes = 0;
    auto server = GeodexServer::Start(options);
    if (!server.ok()) return 1;
    auto channel = grpc::CreateChannel(absl::StrCat("127.0.0.1:", (*server)->port()),
                                       grpc::InsecureChannelCredentials());
    auto stub = v1::Geodex::NewStub(channel);
    if (!Upload(*stub, bytes, mesh_path, "bench").ok()) return 1;
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
    (*server)->Shutdown(absl::Now() + absl::Seconds(30));
  }

  // 2. Query mix from 1, 2 and 4 clients.
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.pool_threads = threads;
  auto server = GeodexServer::Start(options);
  if (!server.ok()) return 1;
  auto channel = grpc::CreateChannel(absl::StrCat("127.0.0.1:", (*server)->port()),
                                     grpc::InsecureChannelCredentials());
  {
    auto stub = v1::Geodex::NewStub(channel);
    if (!Upload(*stub, bytes, mesh_path, "bench").ok()) return 1;
  }
  std::printf("\n2. query mix for %.0f s per row (40%% A* paths, 20%% fields, 20%% point "
              "distances x16, 10%% locate x64, 10%% isolines)\n",
              seconds);
  std::printf("   clients  queries  queries/s   p50 ms   p99 ms   statuses\n");
  for (int clients : {1, 2, 4}) {
    std::atomic<bool> stop{false};
    std::vector<std::future<MixResult>> futures;
    const auto start = Clock::now();
    for (int c = 0; c < clients; ++c) {
      futures.push_back(std::async(std::launch::async, RunClient, channel, std::cref(mesh),
                                   std::cref(data->positions), seed * 100 + c, std::cref(stop)));
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    stop = true;
    MixResult all;
    for (auto& f : futures) {
      MixResult r = f.get();
      all.latencies_ms.insert(all.latencies_ms.end(), r.latencies_ms.begin(), r.latencies_ms.end());
      for (const auto& [k, v] : r.statuses) all.statuses[k] += v;
      all.queries += r.queries;
    }
    const double elapsed = Ms(Clock::now() - start) / 1e3;
    std::string statuses;
    for (const auto& [k, v] : all.statuses) absl::StrAppend(&statuses, k, "=", v, " ");
    std::printf("   %7d  %7d  %9.1f  %7.1f  %7.1f   %s\n", clients, all.queries,
                all.queries / elapsed, Percentile(all.latencies_ms, 0.5),
                Percentile(all.latencies_ms, 0.99), statuses.c_str());
  }

  // 3. Health while every worker is busy with full fields (distinct sources: no cache hits).
  {
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
    while ((*server)->pool().busy() < static_cast<size_t>(threads)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    grpc::GenericStub generic(channel);
    std::vector<double> health;
    int busy_samples = 0, failures = 0;
    for (int i = 0; i < 300; ++i) {
      busy_samples += (*server)->pool().busy() == static_cast<size_t>(threads);
      const auto t0 = Clock::now();
      failures += !HealthCheck(generic).ok();
      health.push_back(Ms(Clock::now() - t0));
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    stop = true;
    for (auto& t : load) t.join();
    std::printf("\n3. health checks while all %d workers compute full fields (300 checks, all busy "
                "at %d of them)\n",
                threads, busy_samples);
    std::printf("   p50 %.2f ms   p99 %.2f ms   max %.2f ms   failures %d\n",
                Percentile(health, 0.5), Percentile(health, 0.99),
                *std::max_element(health.begin(), health.end()), failures);
  }
  (*server)->Shutdown(absl::Now() + absl::Seconds(60));

  // 4. Overload: 8 clients against 2 workers and a queue of 2, with health probes alongside.
  //    Designed answer: RESOURCE_EXHAUSTED at once for what does not fit; nothing else fails.
  {
    ServerOptions load_options;
    load_options.listen = "127.0.0.1:0";
    load_options.pool_threads = threads;
    load_options.queue_capacity = 2;
    load_options.mesh_budget_bytes = uint64_t{256} << 20;
    load_options.result_cache_bytes = uint64_t{64} << 20;
    auto load_server = GeodexServer::Start(load_options);
    if (!load_server.ok()) return 1;
    auto load_channel = grpc::CreateChannel(absl::StrCat("127.0.0.1:", (*load_server)->port()),
                                            grpc::InsecureChannelCredentials());
    {
      auto stub = v1::Geodex::NewStub(load_channel);
      if (!Upload(*stub, bytes, mesh_path, "bench").ok()) return 1;
    }
    const uint64_t rss_before_kb = PeakRssKb();
    std::atomic<bool> stop{false};
    std::vector<std::future<MixResult>> futures;
    for (int c = 0; c < 8; ++c) {
      futures.push_back(std::async(std::launch::async, RunClient, load_channel, std::cref(mesh),
                                   std::cref(data->positions), seed * 1000 + c, std::cref(stop)));
    }
    grpc::GenericStub generic(load_channel);
    std::vector<double> health;
    int health_failures = 0;
    const auto start = Clock::now();
    while (Ms(Clock::now() - start) < seconds * 1e3) {
      const auto t0 = Clock::now();
      health_failures += !HealthCheck(generic).ok();
      health.push_back(Ms(Clock::now() - t0));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    stop = true;
    MixResult all;
    for (auto& f : futures) {
      MixResult r = f.get();
      all.latencies_ms.insert(all.latencies_ms.end(), r.latencies_ms.begin(), r.latencies_ms.end());
      for (const auto& [k, v] : r.statuses) all.statuses[k] += v;
      all.queries += r.queries;
    }
    const double elapsed = Ms(Clock::now() - start) / 1e3;
    std::string statuses;
    for (const auto& [k, v] : all.statuses) absl::StrAppend(&statuses, k, "=", v, " ");
    const int ok = all.statuses["OK"];
    const int exhausted = all.statuses[absl::StrCat("code ", int{grpc::StatusCode::RESOURCE_EXHAUSTED})];
    std::printf("\n4. overload for %.0f s: 8 clients, %d workers, queue 2 (mesh budget 256 MiB, "
                "cache 64 MiB)\n",
                seconds, threads);
    std::printf("   answered %d (%.1f/s), refused at once with RESOURCE_EXHAUSTED %d, other errors %d\n",
                ok, ok / elapsed, exhausted, all.queries - ok - exhausted);
    std::printf("   statuses: %s\n", statuses.c_str());
    std::printf("   health during overload: %zu checks, p50 %.2f ms, p99 %.2f ms, max %.2f ms, "
                "failures %d\n",
                health.size(), Percentile(health, 0.5), Percentile(health, 0.99),
                health.empty() ? 0.0 : *std::max_element(health.begin(), health.end()),
                health_failures);
    std::printf("   peak RSS of the process %.0f MiB (before the overload %.0f MiB); store %.1f MiB "
                "of 256, cache %.1f MiB of 64\n",
                PeakRssKb() / 1024.0, rss_before_kb / 1024.0,
                (*load_server)->store().used_bytes() / 1048576.0,
                (*load_server)->cache().bytes() / 1048576.0);
    (*load_server)->Shutdown(absl::Now() + absl::Seconds(60));
  }
  return 0;
}

}  // namespace
}  // namespace geodex::server

int main(int argc, char** argv) { return geodex::server::Main(argc, argv); }
