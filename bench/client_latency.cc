// geodex_client_latency: what a C++ planner sees calling geodexd in a loop. Repeated single-target
// path queries on a warm mesh (uploaded once), for near and far pairs: the client's latency (p50,
// p99, queries per second, one call at a time) and the server's own solve time, so the difference
// is the client's and the wire's overhead. Pairs are chosen from the field of vertex 0, computed
// beforehand by the CLI into DISTANCES_FILE (so that the server has no cached field from vertex 0
// and every query is a solve): near = targets within 10% of the largest distance, far = beyond 50%.
//
//   geodex_client_latency HOST:PORT MESH_FILE DISTANCES_FILE [CALLS_PER_GROUP] [SEED]
// Prints one Markdown table row per group (bench/client_latency.sh drives it with the Python one).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
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
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s HOST:PORT MESH_FILE DISTANCES_FILE [CALLS_PER_GROUP] [SEED]\n",
                 argv[0]);
    return 2;
  }
  const int calls = argc > 4 ? std::atoi(argv[4]) : 50;
  const unsigned seed = argc > 5 ? static_cast<unsigned>(std::atoi(argv[5])) : 1;
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
  std::vector<double> distance;  // from vertex 0, per vertex ("inf" where unreachable)
  std::ifstream in(argv[3]);
  for (std::string word; in >> word;) distance.push_back(std::strtod(word.c_str(), nullptr));
  double max_d = 0;
  for (double d : distance) {
    if (std::isfinite(d)) max_d = std::max(max_d, d);
  }
  // Every query from a start the server has not seen (the second query from one point makes it
  // solve and cache that point's field; a robot's start moves anyway): starts within 5% of D of
  // vertex 0, so that targets within 10% of D of vertex 0 are within 15% of D of the start
  // ("near") and targets beyond 50% are beyond 45% ("far"), by the triangle inequality.
  std::vector<uint32_t> starts, near, far;
  size_t start_candidates = 0;
  for (uint32_t v = 1; v < distance.size(); ++v) {
    const double d = distance[v];
    if (!std::isfinite(d)) continue;
    // The even-numbered candidates; client_latency.py takes the odd ones (a point asked twice
    // would have the server cache its field).
    if (d <= 0.05 * max_d && (start_candidates++ % 2 == 0)) starts.push_back(v);
    if (d <= 0.1 * max_d) near.push_back(v);
    if (d >= 0.5 * max_d) far.push_back(v);
  }
  std::mt19937 random(seed);
  std::shuffle(starts.begin(), starts.end(), random);
  size_t next_start = 0;
  const std::string name = argv[2];
  for (const auto& [group, targets] :
       {std::pair{"near (<= 15% of D)", near}, std::pair{"far (>= 45% of D)", far}}) {
    if (targets.empty()) continue;
    std::vector<double> latency_ms, solve_ms;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls && next_start < starts.size(); ++i) {
      geodex::PathQuery query;
      query.from = geodex::SurfacePoint::AtVertex(starts[next_start++]);
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
    if (latency_ms.empty()) continue;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<double> overhead;
    for (size_t k = 0; k < latency_ms.size(); ++k) overhead.push_back(latency_ms[k] - solve_ms[k]);
    std::printf("| C++ | %s | %s | %zu | %.3f | %.3f | %.1f | %.3f | %.3f |\n", name.c_str(), group,
                latency_ms.size(), Percentile(latency_ms, 0.5), Percentile(latency_ms, 0.99),
                latency_ms.size() / seconds, Percentile(solve_ms, 0.5), Percentile(overhead, 0.5));
  }
  return 0;
}
