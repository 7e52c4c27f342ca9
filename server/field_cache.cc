#include "field_cache.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <tuple>

#include "geodex/solve_key.h"

namespace geodex::server {
namespace {

// Keys whose asks are remembered: a planner's starts, with room (each is about 100 bytes).
constexpr size_t kMaxAskHistory = 4096;

}  // namespace

std::string FieldCacheKey(const std::string& mesh_id, const std::vector<SurfacePoint>& sources,
                          const GeodesicOptions& options) {
  return mesh_id + SolveKey(sources, options);
}

std::string TravelSurfaceKey(const std::string& mesh_id, const GeodesicOptions& options) {
  return "travel graph|" + mesh_id + TravelCostKey(options);  // (a field's key starts with the id)
}

uint64_t FieldBytes(const DistanceField& field) {
  return field.distance.capacity() * sizeof(double) + field.source.capacity() * sizeof(uint32_t) +
         field.internal_distance.capacity() * sizeof(double) +
         field.internal_source.capacity() * sizeof(uint32_t) +
         field.internal_origin.capacity() * sizeof(VertexOrigin) +
         field.sources.capacity() * sizeof(SurfacePoint) + sizeof(DistanceField);
}

template <typename T, typename Usable>
std::shared_ptr<const T> FieldCache::Lookup(const std::string& key,
                                            std::shared_ptr<const T> Entry::*slot, uint64_t* hits,
                                            uint64_t* misses, Usable usable, bool count_miss) {
  if (!enabled()) return nullptr;
  std::lock_guard<std::mutex> lock(mu_);
  auto it = entries_.find(key);
  if (it == entries_.end() || it->second.*slot == nullptr || !usable(*(it->second.*slot))) {
    if (count_miss) {
      NoteAskLocked(key);
      ++*misses;
    }
    return nullptr;
  }
  NoteAskLocked(key);
  ++*hits;
  lru_.splice(lru_.begin(), lru_, it->second.lru);
  return it->second.*slot;
}

std::shared_ptr<const DistanceField> FieldCache::Find(const std::string& key, bool count_miss) {
  return Lookup(
      key, &Entry::field, &hits_, &misses_, [](const DistanceField&) { return true; }, count_miss);
}

void FieldCache::Insert(const std::string& key, std::shared_ptr<const DistanceField> field) {
  const uint64_t bytes = FieldBytes(*field) + key.size();
  if (!enabled() || bytes > budget_bytes_) return;
  std::lock_guard<std::mutex> lock(mu_);
  InsertLocked(key, Entry{std::move(field), nullptr, bytes, {}});
}

std::shared_ptr<const WeightedSurface> FieldCache::FindGraph(const std::string& key,
                                                             const TriangleMesh& mesh) {
  return Lookup(key, &Entry::graph, &graph_hits_, &graph_misses_,
                [&mesh](const WeightedSurface& graph) { return &graph.mesh() == &mesh; });
}

void FieldCache::InsertGraph(const std::string& key, std::shared_ptr<const WeightedSurface> graph,
                             uint64_t mesh_bytes) {
  const uint64_t bytes = graph->bytes() + mesh_bytes + key.size();
  if (!enabled() || bytes > budget_bytes_) return;
  std::lock_guard<std::mutex> lock(mu_);
  if (auto old = entries_.find(key); old != entries_.end()) {
    bytes_ -= old->second.bytes;
    lru_.erase(old->second.lru);
    entries_.erase(old);
  }
  InsertLocked(key, Entry{nullptr, std::move(graph), bytes, {}});
}

void FieldCache::InsertLocked(const std::string& key, Entry entry) {
  if (entries_.contains(key)) return;
  if (bytes_ + entry.bytes > budget_bytes_) {
    // Room is made from the least-asked entries, least recently used first among equals (lru_ is
    // most recent first); none is evicted for a key asked less often than it.
    std::vector<std::tuple<uint32_t, size_t, const std::string*>> order;
    order.reserve(lru_.size());
    size_t age = 0;
    for (auto it = lru_.rbegin(); it != lru_.rend(); ++it)
      order.emplace_back(AsksLocked(*it), age++, &*it);
    std::sort(order.begin(), order.end());
    const uint32_t asks = AsksLocked(key);
    uint64_t freed = 0;
    size_t victims = 0;
    while (bytes_ - freed + entry.bytes > budget_bytes_ && victims < order.size()) {
      if (std::get<0>(order[victims]) > asks) {
        ++declined_;
        return;
      }
      freed += entries_.find(*std::get<2>(order[victims]))->second.bytes;
      ++victims;
    }
    std::vector<std::string> evicted;
    for (size_t i = 0; i < victims; ++i) evicted.push_back(*std::get<2>(order[i]));
    for (const std::string& victim_key : evicted) {
      auto victim = entries_.find(victim_key);
      bytes_ -= victim->second.bytes;
      lru_.erase(victim->second.lru);
      entries_.erase(victim);
    }
  }
  lru_.push_front(key);
  entry.lru = lru_.begin();
  bytes_ += entry.bytes;
  entries_[key] = std::move(entry);
}

void FieldCache::NoteAskLocked(const std::string& key) {
  if (!asks_.contains(key) && asks_.size() >= kMaxAskHistory) {
    // Recent demand counts: halve every count and forget the keys that reach 0.
    for (auto it = asks_.begin(); it != asks_.end();) {
      it->second /= 2;
      if (it->second == 0) {
        asks_.erase(it++);
      } else {
        ++it;
      }
    }
  }
  if (asks_.size() < kMaxAskHistory || asks_.contains(key)) ++asks_[key];
}

uint32_t FieldCache::AsksLocked(const std::string& key) const {
  auto it = asks_.find(key);
  return it == asks_.end() ? 0 : it->second;
}

bool FieldCache::Contains(const std::string& key) const {
  std::lock_guard<std::mutex> lock(mu_);
  auto it = entries_.find(key);
  return it != entries_.end() && it->second.field != nullptr;
}

bool FieldCache::NotePathSource(const std::string& key) {
  if (!enabled()) return false;
  std::lock_guard<std::mutex> lock(mu_);
  return AsksLocked(key) >= 2;  // the Find that missed counted this ask
}

uint32_t FieldCache::asks(const std::string& key) const {
  std::lock_guard<std::mutex> lock(mu_);
  return AsksLocked(key);
}

uint64_t FieldCache::declined() const {
  std::lock_guard<std::mutex> lock(mu_);
  return declined_;
}

uint64_t FieldCache::bytes() const {
  std::lock_guard<std::mutex> lock(mu_);
  return bytes_;
}
size_t FieldCache::entries() const {
  std::lock_guard<std::mutex> lock(mu_);
  return entries_.size();
}
uint64_t FieldCache::hits() const {
  std::lock_guard<std::mutex> lock(mu_);
  return hits_;
}
uint64_t FieldCache::misses() const {
  std::lock_guard<std::mutex> lock(mu_);
  return misses_;
}
uint64_t FieldCache::graph_hits() const {
  std::lock_guard<std::mutex> lock(mu_);
  return graph_hits_;
}
uint64_t FieldCache::graph_misses() const {
  std::lock_guard<std::mutex> lock(mu_);
  return graph_misses_;
}

}  // namespace geodex::server
