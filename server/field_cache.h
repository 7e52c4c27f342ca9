#pragma once

// The result cache: finished distance fields under a byte budget, keyed by mesh id, the resolved
// sources and the solver options. What it keeps is chosen by what is asked repeatedly: every
// look-up counts an ask of its key (hit or miss; the counts are halved when the history is full,
// so they measure recent demand), a full cache evicts its least-asked entries first (least
// recently used among equals), and declines a new entry rather than evict one asked more often
// (a one-off solve never pushes out a field a planner keeps asking for). Many queries from one
// source position (a robot asking for paths to many goals, isolines then Voronoi of the same sites)
// reuse one solve. Fields are immutable and shared (shared_ptr), so eviction never disturbs a
// reader. Thread-safe.
//
// The same budget holds travel graphs (the weighted engine's Steiner points for one mesh and one
// constant-speed travel cost, core's BuildTravelSurface), keyed by TravelSurfaceKey: the travel
// paths, times at points and matrices on a mesh with one cost layer share one graph instead of each
// building its own.

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "geodex/weighted_field.h"

namespace geodex::server {

// The key of a field: the mesh id and core's SolveKey (geodex/solve_key.h: every source and every
// option that changes the answer, the travel cost included), the rule the CLI's cache keeps too.
std::string FieldCacheKey(const std::string& mesh_id, const std::vector<SurfacePoint>& sources,
                          const GeodesicOptions& options);

// The key of a travel graph: mesh id and the travel cost as FieldCacheKey keys it (no sources).
std::string TravelSurfaceKey(const std::string& mesh_id, const GeodesicOptions& options);

// Memory a cached field occupies.
uint64_t FieldBytes(const DistanceField& field);

class FieldCache {
 public:
  // budget_bytes = 0 disables the cache (Find always misses, Insert keeps nothing).
  explicit FieldCache(uint64_t budget_bytes) : budget_bytes_(budget_bytes) {}

  // `count_miss` false: a miss is not counted as an ask (a quick-lane look-up whose request goes
  // on to the solve lane, which asks again: one request, one ask).
  std::shared_ptr<const DistanceField> Find(const std::string& key, bool count_miss = true);
  // Keeps `field` unless it alone exceeds the budget or making room would evict an entry asked
  // for more often than `key`; evicts the least-asked entries (least recently used first).
  void Insert(const std::string& key, std::shared_ptr<const DistanceField> field);
  // A travel graph. Its owner keeps the mesh it refers to alive, so the entry counts that mesh's
  // `mesh_bytes` too (the mesh store may evict or delete the mesh meanwhile: the budget still
  // bounds what the cache holds). FindGraph answers only a graph built on `mesh` itself: a graph
  // of a mesh since reloaded as another object counts as a miss, and InsertGraph replaces it.
  std::shared_ptr<const WeightedSurface> FindGraph(const std::string& key,
                                                   const TriangleMesh& mesh);
  void InsertGraph(const std::string& key, std::shared_ptr<const WeightedSurface> graph,
                   uint64_t mesh_bytes);
  // After a missed Find(key) by a path query: true when `key` was asked for before (the source
  // is then offered for a background field, FieldPromoter).
  bool NotePathSource(const std::string& key);
  // How often `key` was asked for recently (Find and FindGraph, hit or miss).
  uint32_t asks(const std::string& key) const;
  // Entries not kept because making room would have evicted more-asked ones.
  uint64_t declined() const;

  // Whether `key` holds a field now (not counted as a hit or a miss).
  bool Contains(const std::string& key) const;

  bool enabled() const { return budget_bytes_ > 0; }
  uint64_t budget_bytes() const { return budget_bytes_; }
  uint64_t bytes() const;
  size_t entries() const;
  uint64_t hits() const;
  uint64_t misses() const;
  uint64_t graph_hits() const;
  uint64_t graph_misses() const;

 private:
  struct Entry {
    std::shared_ptr<const DistanceField> field;  // one of the two
    std::shared_ptr<const WeightedSurface> graph;
    uint64_t bytes = 0;
    std::list<std::string>::iterator lru;
  };
  const uint64_t budget_bytes_;
  mutable std::mutex
      mu_;  // (std::mutex: visible to ThreadSanitizer; members below are guarded by it)
  absl::flat_hash_map<std::string, Entry> entries_;
  std::list<std::string> lru_;  // most recent first
  uint64_t bytes_ = 0;
  uint64_t hits_ = 0;
  uint64_t misses_ = 0;
  uint64_t graph_hits_ = 0;
  uint64_t graph_misses_ = 0;
  uint64_t declined_ = 0;
  void InsertLocked(const std::string& key, Entry entry);
  void NoteAskLocked(const std::string& key);
  uint32_t AsksLocked(const std::string& key) const;
  // The look-up both kinds share: `key`'s entry of one kind (`slot`), when `usable` accepts it,
  // moved to the front and counted in `*hits`; else nullptr, counted in `*misses`.
  template <typename T, typename Usable>
  std::shared_ptr<const T> Lookup(const std::string& key, std::shared_ptr<const T> Entry::*slot,
                                  uint64_t* hits, uint64_t* misses, Usable usable,
                                  bool count_miss = true);
  // Asks per key, bounded: at kMaxAskHistory keys every count is halved and the zeros dropped.
  absl::flat_hash_map<std::string, uint32_t> asks_;
};

}  // namespace geodex::server
