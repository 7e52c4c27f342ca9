// geodex_client_latency: what a C++ planner sees calling geodexd in a loop. Repeated single-target
// path queries on a warm mesh (uploaded once), for near and far pairs: the client's latency (p50,
// p99, queries per second, one call at a time) and the server's own solve time, so the difference
// is the client's and the wire's overhead. Pairs are chosen from the field of vertex 0: near =
// targets within 10% of the largest distance, far = beyond 50%.
//
//   geodex_client_latency HOST:PORT MESH_FILE [CALLS_PER_GROUP] [SEED]
// Prints one Markdown table row per group (bench/client_latency.sh drives it with the Python one).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "geodex/geodex_client.h"
#include "geodex/shortest_path.h"

namespace {

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s HOST:PORT MESH_FILE [CALLS_PER_GROUP] [SEED]\n", argv[0]);
    return 2;
  }
  const int calls = argc > 3 ? std::atoi(argv[3]) : 50;
  const unsigned seed = argc > 4 ? static_cast<unsigned>(std::atoi(argv[4])) : 1;
  geodex::client::ClientOptions options;
  options.target = argv[1];
  options.deadline_seconds = 120;
  options.wait_for_ready = true;
  geodex::client::GeodexClient client(options);
  absl::StatusOr<geodex::client::MeshRef> mesh = client.ResolveMesh(argv[2]);
  if (!mesh.ok()) {
    std::fprintf(stderr, "%s\n", mesh.status().ToString().c_str());
    return 1;
  }
  geodex::FieldQuery field_query;
  field_query.sources = {geodex::SurfacePoint::AtVertex(0)};
  absl::StatusOr<geodex::DistanceField> field = client.Field(*mesh, field_query);
  if (!field.ok()) {
    std::fprintf(stderr, "%s\n", field.status().ToString().c_str());
    return 1;
  }
  double max_d = 0;
  for (double d : field->distance) {
    if (std::isfinite(d)) max_d = std::max(max_d, d);
  }
  std::vector<uint32_t> near, far;
  for (uint32_t v = 1; v < field->distance.size(); ++v) {
    const double d = field->distance[v];
    if (!std::isfinite(d)) continue;
    if (d <= 0.1 * max_d) near.push_back(v);
    if (d >= 0.5 * max_d) far.push_back(v);
  }
  std::mt19937 random(seed);
  const std::string name = argv[2];
  for (const auto& [group, targets] :
       {std::pair{"near (<= 10% of D)", near}, std::pair{"far (>= 50% of D)", far}}) {
    if (targets.empty()) continue;
    std::vector<double> latency_ms, solve_ms;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) {
      geodex::PathQuery query;
      query.from = geodex::SurfacePoint::AtVertex(0);
      query.to = geodex::SurfacePoint::AtVertex(targets[random() % targets.size()]);
      const auto t0 = std::chrono::steady_clock::now();
      absl::StatusOr<geodex::PathQueryResult> path = client.ShortestPath(*mesh, query);
      latency_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (!path.ok()) {
        std::fprintf(stderr, "%s\n", path.status().ToString().c_str());
        return 1;
      }
      solve_ms.push_back(path->stats.solve_ms);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("| C++ | %s | %s | %d | %.3f | %.3f | %.1f | %.3f | %.3f |\n", name.c_str(), group,
                calls, Percentile(latency_ms, 0.5), Percentile(latency_ms, 0.99), calls / seconds,
                Percentile(solve_ms, 0.5), Percentile(latency_ms, 0.5) - Percentile(solve_ms, 0.5));
  }
  return 0;
}
