#pragma once

// How the regions of a weighted surface meet, for the engine running on their union
// (weighted_regions.h): each region of one weight is its own component of the mesh the engine
// runs on, scaled by its weight, so every length there is a cost; the components touch only
// through these links.

#include <array>
#include <cstdint>
#include <vector>

namespace geodex::ich {

// A path's origin at a boundary point rather than a vertex (VertexOrigin::pseudo_source |
// kBoundaryPointTag = the point's index): what a window emitted by a boundary point carries as its
// pseudo-source, so that a path traced back through the union continues from that point
// (IchSolver::point_origins(), path_trace.h).
inline constexpr uint32_t kBoundaryPointTag = 1u << 31;
inline bool IsBoundaryPoint(uint32_t pseudo_source) {
  return pseudo_source != 0xffffffffu && (pseudo_source & kBoundaryPointTag) != 0;
}

struct RegionLinks {
  // Per half-edge of the union mesh: the chain of boundary points on it (kNoIndex: none), and
  // whether the chain runs from the half-edge's end to its start.
  std::vector<uint32_t> chain_of_half;
  std::vector<uint8_t> chain_reversed;
  // Chain c's points are [chain_first[c], chain_first[c + 1]), at increasing parameters in (0, 1).
  std::vector<uint32_t> chain_first;
  std::vector<double> point_param;
  std::vector<uint32_t> point_chain;
  // Chain c: the cost of running along it per unit of parameter (its length x the smaller weight
  // of its two faces), and its half-edges in the two regions it separates with the same cost at
  // each one's weight (the smaller one is chain_cost bit for bit, so a cost passed along the chain
  // compares exactly with a way along the edge at that side's weight).
  std::vector<double> chain_cost;
  std::vector<std::array<uint32_t, 2>> chain_halves;
  std::vector<std::array<double, 2>> side_cost;
  // Per vertex of the union mesh: the next copy of the same vertex of the surface, in a ring
  // (itself when it has none). Copies share their cost.
  std::vector<uint32_t> next_copy;

  uint32_t point_count() const { return static_cast<uint32_t>(point_param.size()); }
  uint64_t bytes() const {
    auto of = [](const auto& v) { return uint64_t{v.capacity()} * sizeof(v[0]); };
    return of(chain_of_half) + of(chain_reversed) + of(chain_first) + of(point_param) +
           of(point_chain) + of(chain_cost) + of(chain_halves) + of(side_cost) + of(next_copy);
  }
};

}  // namespace geodex::ich
