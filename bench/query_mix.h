#pragma once

// What the service benchmarks share: a closed-loop client running a realistic query mix against a
// geodexd, counting gRPC statuses (never HTTP ones), and the small timing helpers around it.
//
// The mix, per query: 40% A* paths between random vertices, 20% full distance fields, 20% point
// distances (estimate and exact at 16 face points), 10% locate (64 positions), 10% isolines (8).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "geodex/v1/geodex.grpc.pb.h"
#include "grpcpp/channel.h"
#include "grpcpp/generic/generic_stub.h"

namespace geodex::bench {

using Clock = std::chrono::steady_clock;

double Ms(Clock::duration d);
// The p-quantile (0..1) of `v`, nearest rank; 0 for an empty sample.
double Percentile(std::vector<double> v, double p);
std::chrono::system_clock::time_point In(double seconds);

// Uploads `bytes` (a mesh file named `file_name`) under `alias` in 1 MiB chunks.
grpc::Status Upload(v1::Geodex::Stub& stub, const std::string& bytes, const std::string& file_name,
                    const std::string& alias, v1::Mesh* created = nullptr);
// One grpc.health.v1.Health/Check of the overall status (empty request), deadline 30 s.
grpc::Status HealthCheck(grpc::GenericStub& stub);

// A mesh the mix queries: its resource name and what the client needs to pick valid inputs.
struct MixMesh {
  std::string name;       // "meshes/<alias>"
  uint32_t vertices = 0;  // file vertices
  uint32_t faces = 0;
  std::vector<double> positions;  // file coordinates, 3 per vertex (for LocatePoints)
};

struct MixResult {
  std::vector<double> latencies_ms;                    // every query
  std::map<std::string, std::vector<double>> kind_ms;  // OK queries, by kind ("path", ...)
  std::map<std::string, int> statuses;                 // "OK", "RESOURCE_EXHAUSTED", ...
  int queries = 0;
  void Merge(const MixResult& other);
};

// Runs the mix until `stop`, each query on a mesh picked at random from `meshes`.
MixResult RunMixClient(const std::shared_ptr<grpc::Channel>& channel,
                       const std::vector<MixMesh>& meshes, uint32_t seed,
                       const std::atomic<bool>& stop);

// "OK", "RESOURCE_EXHAUSTED", ... (the canonical names of gRPC status codes).
std::string StatusName(grpc::StatusCode code);

}  // namespace geodex::bench
