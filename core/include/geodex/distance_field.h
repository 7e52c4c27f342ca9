#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "geodex/surface_point.h"

namespace geodex {

inline constexpr double kUnreachable = std::numeric_limits<double>::infinity();

// Counters of one solve; filled in every build (not only debug).
struct SolveStats {
  uint64_t windows_created = 0;  // interval windows made (including ones filtered at once)
  uint64_t windows_filtered_at_creation = 0;  // Lemma 2 (filter theorem) on a new child
  uint64_t windows_filtered_at_pop = 0;       // Lemma 2 again when dequeued (distances improved)
  uint64_t windows_filtered_overfilter = 0;   // removed only because of the lambda margin
  uint64_t children_skipped_one_split = 0;    // Lemma 1: a losing window's second child not made
  uint64_t windows_deleted_one_split = 0;     // Lemma 1: windows of an old owner's removed subtree
  uint64_t windows_processed = 0;             // dequeued and propagated
  uint64_t pseudo_sources = 0;                // pseudo-source windows made (saddle/boundary/source)
  uint64_t pseudo_sources_full_fan = 0;       // processed with windows on every opposite edge
  uint64_t pseudo_sources_shadow_only = 0;  // saddles reached straight through: shadow sector only
  uint64_t edge_relaxations = 0;            // vertex-to-neighbour updates
  uint32_t max_level = 0;                   // deepest window in the sequence tree
  uint64_t peak_live_windows = 0;
  uint64_t peak_bytes = 0;  // window pool + queue + per-vertex arrays at peak
  double solve_ms = 0;
};

// Adds the counters of `s` to `total` (peaks and the deepest level: the larger).
void AddSolveStats(const SolveStats& s, SolveStats* total);

// How a vertex got its distance: straight from the unfolded pseudo-source image (ix, iy) in the
// frame of half-edge `half_edge` (the path crosses that edge into its face and ends at the vertex),
// or along the edge from neighbour `pseudo_source` when half_edge == kNoIndex (edge relaxation or
// a neighbour of a pseudo-source). Enough to backtrace exact paths without keeping windows.
struct VertexOrigin {
  uint32_t half_edge = 0xffffffffu;
  uint32_t pseudo_source = 0xffffffffu;  // the saddle/boundary/source vertex the path bends at
  double ix = 0, iy = 0;
};

// The result of a solve. Per-vertex arrays are in the FILE's vertex order (a file vertex split at
// a non-manifold junction gets the best value over its copies); `internal_*` are per internal
// vertex (see TriangleMesh) and are what paths and other consumers read.
struct DistanceField {
  std::vector<double> distance;  // +inf where unreachable
  std::vector<uint32_t> source;  // index into the source list; 0xffffffff where unreachable
  std::vector<double> internal_distance;
  std::vector<uint32_t> internal_source;
  std::vector<VertexOrigin> internal_origin;
  std::vector<SurfacePoint> sources;  // as given to the solve; labels index this list
  SolveStats stats;
  // The geodesic direction per file vertex, when asked for (ComputeDirectionField in
  // geodex/shortest_path.h; geodexd's want_directions); empty otherwise.
  std::vector<std::array<double, 3>> direction;
  // > 0: a travel-cost field (geodex/travel_cost.h): `distance` holds seconds from the weighted
  // engine, within (1 + travel_epsilon) of the least times, and there are no origins to trace.
  double travel_epsilon = 0;
  // A travel field whose times are exact (TravelIsExact: one weight at a constant speed).
  bool travel_exact = false;
  // geodexd's answers only (the client library): how far each point given as a 3D position
  // (SurfacePoint::kPosition) moved onto the surface, one per source; 0 for a point given on the
  // surface. Core's own queries take surface points and leave it empty.
  std::vector<double> snap_distances;
};

}  // namespace geodex
