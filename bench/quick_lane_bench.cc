// geodex_quick_lane_bench: latency of cheap calls while every solve worker is busy, with the quick
// lane (--quick_threads=2) and without it (--quick_threads=0, the behaviour before it), in one run.
//
//   geodex_quick_lane_bench [--mesh FILE] [--workers W] [--calls N]
//
// For each setting: an in-process geodexd on 127.0.0.1:0 with W solve workers; the mesh is
// uploaded and one field cached; W client threads then keep every worker busy with uncached
// fields (a new source each time) while one client times N calls of each cheap kind, one at a
// time: LocatePoints, the cached field again, and a path traced from the cached field. Reports
// p50/p99/max per kind and setting, and the p99 ratio. docs/performance.md records the figures.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "geodex/mesh_io.h"
#include "geodex_server.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "query_mix.h"

namespace geodex::bench {
namespace {

using Clock = std::chrono::steady_clock;

struct Percentiles {
  double p50 = 0, p99 = 0, max = 0;
};

Percentiles Summarise(const std::vector<double>& ms) {
  return {Percentile(ms, 0.5), Percentile(ms, 0.99), Percentile(ms, 1.0)};
}

grpc::Status Field(v1::Geodex::Stub& stub, const std::string& mesh, uint32_t source) {
  grpc::ClientContext context;
  context.set_deadline(In(600));
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh(mesh);
  request.add_sources()->set_vertex(source);
  request.set_omit_labels(true);
  auto reader = stub.ComputeDistanceField(&context, request);
  v1::ComputeDistanceFieldResponse response;
  while (reader->Read(&response)) {
  }
  return reader->Finish();
}

struct Setting {
  std::string name;
  size_t quick_threads;
  std::vector<Percentiles> kinds;  // locate, cached field, traced path
};

int Main(int argc, char** argv) {
  std::string mesh_path = std::string(GEODEX_SOURCE_DIR) + "/../shared/meshes/armadillo.off";
  int workers = 2, calls = 100;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--mesh")
      mesh_path = value;
    else if (flag == "--workers")
      workers = std::stoi(value);
    else if (flag == "--calls")
      calls = std::stoi(value);
    else {
      std::fprintf(stderr, "unknown flag %s\n", flag.c_str());
      return 2;
    }
  }
  std::ifstream in(mesh_path, std::ios::binary);
  if (!in) mesh_path = std::string(GEODEX_SOURCE_DIR) + "/tests/data/fertility.off";
  in = std::ifstream(mesh_path, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  absl::StatusOr<MeshData> data = ReadMeshFromBuffer(file, MeshFormat::kAuto, mesh_path);
  if (!data.ok()) {
    std::fprintf(stderr, "%s\n", std::string(data.status().message()).c_str());
    return 1;
  }
  const uint32_t vertices = static_cast<uint32_t>(data->vertex_count());
  const auto& pos = data->positions;
  std::printf(
      "mesh %s: %u vertices; %d solve workers busy with uncached fields; %d calls per kind\n",
      mesh_path.c_str(), vertices, workers, calls);

  std::vector<Setting> settings = {{"no quick lane (--quick_threads=0)", 0, {}},
                                   {"quick lane (--quick_threads=2)", 2, {}}};
  for (Setting& setting : settings) {
    server::ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.pool_threads = workers;
    options.quick_threads = setting.quick_threads;
    options.log_requests = false;
    auto server = server::GeodexServer::Start(options);
    if (!server.ok()) {
      std::fprintf(stderr, "%s\n", std::string(server.status().message()).c_str());
      return 1;
    }
    const std::string address = absl::StrCat("127.0.0.1:", (*server)->port());
    auto stub =
        v1::Geodex::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
    v1::Mesh mesh;
    if (grpc::Status s = Upload(*stub, file, mesh_path, "", &mesh); !s.ok()) {
      std::fprintf(stderr, "upload: %s\n", s.error_message().c_str());
      return 1;
    }
    if (!Field(*stub, mesh.name(), 0).ok()) return 1;  // the cached field

    std::atomic<bool> stop{false};
    std::vector<std::thread> busy;
    for (int w = 0; w < workers; ++w) {
      busy.emplace_back([&, w] {
        auto own = v1::Geodex::NewStub(grpc::CreateChannel(
            address, grpc::InsecureChannelCredentials()));  // its own connection
        for (uint32_t k = 1; !stop.load(); ++k) {
          Field(*own, mesh.name(), (k * 7919 + static_cast<uint32_t>(w) * 104729) % vertices);
        }
      });
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the workers are busy

    std::vector<double> locate_ms, field_ms, path_ms;
    for (int i = 0; i < calls; ++i) {
      const uint32_t v = static_cast<uint32_t>((i * 2654435761u) % vertices);
      auto t0 = Clock::now();
      {
        grpc::ClientContext context;
        context.set_deadline(In(600));
        v1::LocatePointsRequest request;
        request.set_mesh(mesh.name());
        v1::Position* p = request.add_positions();
        p->set_x(pos[3 * v]);
        p->set_y(pos[3 * v + 1]);
        p->set_z(pos[3 * v + 2]);
        v1::LocatePointsResponse response;
        stub->LocatePoints(&context, request, &response);
      }
      auto t1 = Clock::now();
      Field(*stub, mesh.name(), 0);
      auto t2 = Clock::now();
      {
        grpc::ClientContext context;
        context.set_deadline(In(600));
        v1::FindShortestPathRequest request;
        request.set_mesh(mesh.name());
        request.mutable_from()->set_vertex(0);
        request.mutable_to()->set_vertex(v);
        v1::FindShortestPathResponse response;
        stub->FindShortestPath(&context, request, &response);
      }
      auto t3 = Clock::now();
      auto ms = [](Clock::duration d) {
        return std::chrono::duration<double, std::milli>(d).count();
      };
      locate_ms.push_back(ms(t1 - t0));
      field_ms.push_back(ms(t2 - t1));
      path_ms.push_back(ms(t3 - t2));
    }
    stop = true;
    for (std::thread& t : busy) t.join();
    setting.kinds = {Summarise(locate_ms), Summarise(field_ms), Summarise(path_ms)};
    (*server)->Shutdown(absl::Now() + absl::Seconds(5));
  }
  const char* kinds[] = {"LocatePoints", "cached field", "path from cached field"};
  std::printf("%-24s %-36s %10s %10s %10s\n", "call", "setting", "p50 ms", "p99 ms", "max ms");
  for (int k = 0; k < 3; ++k) {
    for (const Setting& s : settings) {
      std::printf("%-24s %-36s %10.2f %10.2f %10.2f\n", kinds[k], s.name.c_str(), s.kinds[k].p50,
                  s.kinds[k].p99, s.kinds[k].max);
    }
    std::printf("%-24s p99 without / with the quick lane: %.1fx\n", kinds[k],
                settings[0].kinds[k].p99 / std::max(1e-9, settings[1].kinds[k].p99));
  }
  return 0;
}

}  // namespace
}  // namespace geodex::bench

int main(int argc, char** argv) { return geodex::bench::Main(argc, argv); }
