#include "query_mix.h"

#include <algorithm>
#include <future>
#include <random>

#include "absl/status/status.h"
#include "grpcpp/client_context.h"
#include "grpcpp/support/byte_buffer.h"

namespace geodex::bench {

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

grpc::Status Upload(v1::Geodex::Stub& stub, const std::string& bytes, const std::string& file_name,
                    const std::string& alias, v1::Mesh* created) {
  grpc::ClientContext context;
  context.set_deadline(In(600));
  v1::Mesh mesh;
  auto writer = stub.CreateMesh(&context, &mesh);
  v1::CreateMeshRequest request;
  request.mutable_metadata()->set_file_name(file_name);
  request.mutable_metadata()->set_display_name(alias);
  writer->Write(request);
  for (size_t offset = 0; offset < bytes.size(); offset += 1 << 20) {
    request.Clear();
    request.set_chunk(bytes.substr(offset, 1 << 20));
    if (!writer->Write(request)) break;
  }
  writer->WritesDone();
  grpc::Status status = writer->Finish();
  if (created != nullptr) *created = mesh;
  return status;
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

void MixResult::Merge(const MixResult& other) {
  latencies_ms.insert(latencies_ms.end(), other.latencies_ms.begin(), other.latencies_ms.end());
  for (const auto& [kind, ms] : other.kind_ms) {
    kind_ms[kind].insert(kind_ms[kind].end(), ms.begin(), ms.end());
  }
  for (const auto& [name, count] : other.statuses) statuses[name] += count;
  queries += other.queries;
}

std::string StatusName(grpc::StatusCode code) {
  const std::string name = absl::StatusCodeToString(static_cast<absl::StatusCode>(code));
  return name.empty() ? "code " + std::to_string(static_cast<int>(code)) : name;
}

MixResult RunMixClient(const std::shared_ptr<grpc::Channel>& channel,
                       const std::vector<MixMesh>& meshes, uint32_t seed,
                       const std::atomic<bool>& stop) {
  auto stub = v1::Geodex::NewStub(channel);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<size_t> which(0, meshes.size() - 1);
  std::uniform_int_distribution<uint32_t> kind(0, 9);
  std::uniform_real_distribution<double> unit(0.05, 0.9);
  MixResult result;
  while (!stop.load()) {
    const MixMesh& mesh = meshes[which(rng)];
    auto vertex = [&] {
      return std::uniform_int_distribution<uint32_t>(0, mesh.vertices - 1)(rng);
    };
    auto face_point = [&](v1::SurfacePoint* p) {
      const double a = unit(rng), b = unit(rng) * (1 - a);
      auto* f = p->mutable_face();
      f->set_face(std::uniform_int_distribution<uint32_t>(0, mesh.faces - 1)(rng));
      f->set_b0(a);
      f->set_b1(b);
      f->set_b2(1 - a - b);
    };
    const uint32_t k = kind(rng);
    const auto start = Clock::now();
    grpc::Status status;
    grpc::ClientContext context;
    context.set_deadline(In(600));
    std::string name;
    if (k < 4) {
      name = "path";
      v1::FindShortestPathRequest request;
      request.set_mesh(mesh.name);
      request.mutable_from()->set_vertex(vertex());
      request.mutable_to()->set_vertex(vertex());
      v1::FindShortestPathResponse response;
      status = stub->FindShortestPath(&context, request, &response);
    } else if (k < 6) {
      name = "field";
      v1::ComputeDistanceFieldRequest request;
      request.set_mesh(mesh.name);
      request.add_sources()->set_vertex(vertex());
      auto reader = stub->ComputeDistanceField(&context, request);
      v1::ComputeDistanceFieldResponse response;
      while (reader->Read(&response)) {
      }
      status = reader->Finish();
    } else if (k < 8) {
      name = "points";
      v1::EstimateDistancesRequest request;
      request.set_mesh(mesh.name);
      request.add_sources()->set_vertex(vertex());
      for (int i = 0; i < 16; ++i) face_point(request.add_points());
      request.set_mode(v1::POINT_DISTANCE_MODE_BOTH);
      v1::EstimateDistancesResponse response;
      status = stub->EstimateDistances(&context, request, &response);
    } else if (k < 9) {
      name = "locate";
      v1::LocatePointsRequest request;
      request.set_mesh(mesh.name);
      for (int i = 0; i < 64; ++i) {
        const double* p = &mesh.positions[3 * size_t{vertex()}];
        auto* q = request.add_positions();
        q->set_x(p[0] + 0.01);
        q->set_y(p[1] - 0.01);
        q->set_z(p[2]);
      }
      v1::LocatePointsResponse response;
      status = stub->LocatePoints(&context, request, &response);
    } else {
      name = "isolines";
      v1::ComputeIsolinesRequest request;
      request.set_mesh(mesh.name);
      request.add_sources()->set_vertex(vertex());
      request.set_count(8);
      auto reader = stub->ComputeIsolines(&context, request);
      v1::ComputeIsolinesResponse response;
      while (reader->Read(&response)) {
      }
      status = reader->Finish();
    }
    const double ms = Ms(Clock::now() - start);
    result.latencies_ms.push_back(ms);
    if (status.ok()) result.kind_ms[name].push_back(ms);
    ++result.statuses[StatusName(status.error_code())];
    ++result.queries;
  }
  return result;
}

}  // namespace geodex::bench
