#include "field_cache.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <tuple>

#include "geodex/mesh_id.h"

namespace geodex::server {
namespace {

// Keys whose asks are remembered: a planner's starts, with room (each is about 100 bytes).
constexpr size_t kMaxAskHistory = 4096;

template <typename T>
void Append(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof value);
}

using Weights = std::shared_ptr<const std::vector<double>>;

// The SHA-256 of a travel cost's face weights. One request keys many fields with the same weights
// (a matrix's rows, a batch's sources), and friction from the cache is one vector for many
// requests, so each thread remembers the last weights it hashed: the same vector (the same
// address under the same control block, still alive: immutable) has the same digest.
std::array<uint8_t, 32> WeightsDigest(const Weights& weights) {
  thread_local std::weak_ptr<const std::vector<double>> last;
  thread_local const std::vector<double>* last_address = nullptr;
  thread_local std::array<uint8_t, 32> last_digest{};
  if (!last.expired() && last_address == weights.get() && !last.owner_before(weights) &&
      !weights.owner_before(last)) {
    return last_digest;
  }
  Sha256 sha;
  sha.Update(weights->data(), weights->size() * sizeof(double));
  last_digest = sha.Finish();
  last = weights;
  last_address = weights.get();
  return last_digest;
}

// A travel field is never another field: a marker byte, then its speed model, speed, table
// (row count, then the rows), direction (inbound, for a slope speed), bound, slope limit and
// weights (by their SHA-256; the friction polygons count by the weights they made).
void AppendTravel(std::string* out, const GeodesicOptions& options) {
  std::string& key = *out;
  Append(&key, static_cast<uint8_t>(options.travel.has_value()));
  if (options.travel) {
    const TravelCost& travel = *options.travel;
    Append(&key, static_cast<uint8_t>(travel.speed_model));
    Append(&key, travel.speed_kmh);
    const size_t rows = travel.speed_table == nullptr ? 0 : travel.speed_table->size();
    Append(&key, rows);
    for (size_t i = 0; i < rows; ++i) Append(&key, (*travel.speed_table)[i]);
    Append(&key, static_cast<uint8_t>(TimesInbound(travel)));  // (one entry at a constant speed)
    Append(&key, TravelEpsilon(travel));  // (unset and its default are one entry)
    Append(&key, travel.max_slope_deg);
    const bool weighted = travel.face_weight != nullptr;
    Append(&key, static_cast<uint8_t>(weighted));
    if (weighted) {
      Append(&key, travel.face_weight->size());
      Append(&key, WeightsDigest(travel.face_weight));
    }
  }
}

}  // namespace

std::string FieldCacheKey(const std::string& mesh_id, const std::vector<SurfacePoint>& sources,
                          const GeodesicOptions& options) {
  std::string key = mesh_id;
  Append(&key, options.lambda);
  Append(&key, static_cast<int>(options.lambda_scale));
  Append(&key, options.max_distance);
  AppendTravel(&key, options);
  Append(&key, sources.size());
  for (const SurfacePoint& p : sources) {
    Append(&key, static_cast<uint8_t>(p.kind));
    switch (p.kind) {
      case SurfacePoint::Kind::kVertex:
        Append(&key, p.vertex);
        break;
      case SurfacePoint::Kind::kEdge:
        Append(&key, p.edge_from);
        Append(&key, p.edge_to);
        Append(&key, p.t);
        break;
      case SurfacePoint::Kind::kFace:
        Append(&key, p.face);
        Append(&key, p.bary);
        break;
      case SurfacePoint::Kind::kPosition:
        Append(&key, p.position);
        break;
    }
  }
  return key;
}

std::string TravelGraphKey(const std::string& mesh_id, const GeodesicOptions& options) {
  std::string key = "travel graph|" + mesh_id;  // (a field's key starts with the bare id)
  AppendTravel(&key, options);
  return key;
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
                                                             const TriangleMesh& mesh,
                                                             bool any_point) {
  return Lookup(key, &Entry::graph, &graph_hits_, &graph_misses_,
                [&mesh, any_point](const WeightedSurface& graph) {
                  return &graph.mesh() == &mesh && (!any_point || graph.ServesAnyPoint());
                });
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
