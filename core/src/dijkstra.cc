#include "dijkstra.h"

#include <algorithm>
#include <chrono>
#include <utility>

namespace geodex {

absl::Status RunDijkstra(const TriangleMesh& mesh, const std::vector<VertexSeed>& seeds,
                         const GeodesicOptions& options, DistanceField* out) {
  const auto start = std::chrono::steady_clock::now();
  const uint32_t nv = mesh.vertex_count();
  std::vector<double> dist(nv, kUnreachable);
  std::vector<uint32_t> label(nv, kNoIndex);
  std::vector<VertexOrigin> origin(nv);
  using Entry = std::pair<double, uint32_t>;  // (distance, vertex); ties broken by vertex id
  std::vector<Entry> heap;
  heap.reserve(nv);
  auto push = [&](double d, uint32_t v) {
    heap.emplace_back(d, v);
    std::push_heap(heap.begin(), heap.end(), std::greater<Entry>());
  };
  for (const VertexSeed& s : seeds) {
    if (s.distance < dist[s.vertex]) {
      dist[s.vertex] = s.distance;
      label[s.vertex] = s.label;
      origin[s.vertex] = VertexOrigin{kNoIndex, s.vertex, 0, 0};
      push(s.distance, s.vertex);
    }
  }
  uint32_t polls = 0;
  uint64_t relaxations = 0;
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), std::greater<Entry>());
    const auto [d, v] = heap.back();
    heap.pop_back();
    if (d != dist[v]) continue;
    if (d > options.max_distance) break;
    if (++polls == 4096) {
      polls = 0;
      if (options.cancel != nullptr && options.cancel->IsCancelled()) {
        return absl::CancelledError("geodesic solve cancelled");
      }
    }
    for (uint32_t i = mesh.NeighborBegin(v); i < mesh.NeighborEnd(v); ++i) {
      const uint32_t u = mesh.NeighborVertex(i);
      const double du = d + mesh.NeighborLength(i);
      if (du < dist[u]) {
        ++relaxations;
        dist[u] = du;
        label[u] = label[v];
        origin[u] = VertexOrigin{kNoIndex, v, 0, 0};
        push(du, u);
      }
    }
  }
  for (uint32_t v = 0; v < nv; ++v) {
    if (dist[v] > options.max_distance) {
      dist[v] = kUnreachable;
      label[v] = kNoIndex;
      origin[v] = VertexOrigin{};
    }
  }
  out->stats = SolveStats{};
  out->stats.edge_relaxations = relaxations;
  out->stats.peak_bytes = heap.capacity() * sizeof(Entry) +
                          nv * (sizeof(double) + sizeof(uint32_t) + sizeof(VertexOrigin));
  out->internal_distance = std::move(dist);
  out->internal_source = std::move(label);
  out->internal_origin = std::move(origin);
  out->stats.solve_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return absl::OkStatus();
}

}  // namespace geodex
