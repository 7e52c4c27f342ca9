// The weighted engine's search (private to core): Dijkstra, or A* towards targets, over the
// implicit Steiner graph with a queue of buckets and a branch-free filter of a chain's candidate
// nodes (SSE2, AVX2 where the CPU has it), and what searches with targets need: the best link to a
// target, the goal a search heads for, the watch that stops it once every target is final.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "geodex/limits.h"
#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"
#include "weighted/cost_models.h"
#include "weighted/steiner_graph.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define GEODEX_AVX2_FILTER 1  // MarkCandidatesAvx2, chosen at run time
#endif

namespace geodex::weighted_internal {

// An allocator that leaves elements default-initialised: a vector of doubles resized with it is
// not written, so its pages are only mapped where a search writes them (Search's headed state).
template <typename T>
struct UninitializedAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <typename U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <typename T>
using LazyVector = std::vector<T, UninitializedAllocator<T>>;

// Where a search is headed (A*): a ball around its targets and a least cost per metre of any
// link, so that per_metre x (the distance to the ball) is a lower bound of the cost left: a
// consistent heuristic (a link costs at least per_metre x its length, which is at least the
// change in that distance).
struct Goal {
  Vec centre{};
  double radius = 0;
  double per_metre = 0;
};

// Bit j of the result: node j of a chain (cost c[j], at a + t[j] d relative to the settled point)
// might be improved by a link from the settled point, of cost `base` + length x at least
// 1 / per_metre: the link's squared length is below the node's room squared, loosened by 1e-9 so
// rounding never drops an improvement. Settled nodes (c[j] <= base) and nodes already cheaper
// than any link could make them are not marked. count <= 64.
constexpr double kSlack = 1 + 1e-9;

// MarkCandidates' test for nodes j.. count-1, one at a time.
inline uint64_t MarkRest(const double* c, const double* t, uint32_t j, uint32_t count, double base,
                         double per_metre, const Vec& a, const Vec& d) {
  uint64_t hits = 0;
  for (; j < count; ++j) {
    const double room = (c[j] - base) * per_metre;
    const double x = a[0] + t[j] * d[0], y = a[1] + t[j] * d[1], z = a[2] + t[j] * d[2];
    const bool hit = (room > 0) & (x * x + y * y + z * z < room * room * kSlack);
    hits |= uint64_t{hit} << j;
  }
  return hits;
}

inline uint64_t MarkCandidates(const double* c, const double* t, uint32_t count, double base,
                               double per_metre, const Vec& a, const Vec& d) {
  uint64_t hits = 0;
  uint32_t j = 0;
#if defined(__SSE2__)
  const __m128d vbase = _mm_set1_pd(base), vper = _mm_set1_pd(per_metre);
  const __m128d vslack = _mm_set1_pd(kSlack), zero = _mm_setzero_pd();
  const __m128d ax = _mm_set1_pd(a[0]), ay = _mm_set1_pd(a[1]), az = _mm_set1_pd(a[2]);
  const __m128d dx = _mm_set1_pd(d[0]), dy = _mm_set1_pd(d[1]), dz = _mm_set1_pd(d[2]);
  for (; j + 2 <= count; j += 2) {
    const __m128d room = _mm_mul_pd(_mm_sub_pd(_mm_loadu_pd(c + j), vbase), vper);
    const __m128d s = _mm_loadu_pd(t + j);
    const __m128d x = _mm_add_pd(ax, _mm_mul_pd(s, dx));
    const __m128d y = _mm_add_pd(ay, _mm_mul_pd(s, dy));
    const __m128d z = _mm_add_pd(az, _mm_mul_pd(s, dz));
    const __m128d len2 =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(x, x), _mm_mul_pd(y, y)), _mm_mul_pd(z, z));
    const __m128d hit = _mm_and_pd(_mm_cmpgt_pd(room, zero),
                                   _mm_cmplt_pd(len2, _mm_mul_pd(_mm_mul_pd(room, room), vslack)));
    hits |= uint64_t(_mm_movemask_pd(hit)) << j;
  }
#endif
  return hits | MarkRest(c, t, j, count, base, per_metre, a, d);
}

#if defined(GEODEX_AVX2_FILTER)
// MarkCandidates four nodes per instruction, the same operations per lane (AVX2 without FMA: no
// contraction), so the same marks. Called only where the CPU has AVX2 (kHasAvx2).
inline __attribute__((target("avx2"))) uint64_t MarkCandidatesAvx2(const double* c, const double* t,
                                                                   uint32_t count, double base,
                                                                   double per_metre, const Vec& a,
                                                                   const Vec& d) {
  uint64_t hits = 0;
  uint32_t j = 0;
  const __m256d vbase = _mm256_set1_pd(base), vper = _mm256_set1_pd(per_metre);
  const __m256d vslack = _mm256_set1_pd(kSlack), zero = _mm256_setzero_pd();
  const __m256d ax = _mm256_set1_pd(a[0]), ay = _mm256_set1_pd(a[1]), az = _mm256_set1_pd(a[2]);
  const __m256d dx = _mm256_set1_pd(d[0]), dy = _mm256_set1_pd(d[1]), dz = _mm256_set1_pd(d[2]);
  for (; j + 4 <= count; j += 4) {
    const __m256d room = _mm256_mul_pd(_mm256_sub_pd(_mm256_loadu_pd(c + j), vbase), vper);
    const __m256d s = _mm256_loadu_pd(t + j);
    const __m256d x = _mm256_add_pd(ax, _mm256_mul_pd(s, dx));
    const __m256d y = _mm256_add_pd(ay, _mm256_mul_pd(s, dy));
    const __m256d z = _mm256_add_pd(az, _mm256_mul_pd(s, dz));
    const __m256d len2 =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), _mm256_mul_pd(z, z));
    const __m256d hit = _mm256_and_pd(
        _mm256_cmp_pd(room, zero, _CMP_GT_OQ),
        _mm256_cmp_pd(len2, _mm256_mul_pd(_mm256_mul_pd(room, room), vslack), _CMP_LT_OQ));
    hits |= uint64_t(_mm256_movemask_pd(hit)) << j;
  }
  return hits | MarkRest(c, t, j, count, base, per_metre, a, d);
}

inline const bool kHasAvx2 = __builtin_cpu_supports("avx2");
#endif

// Dijkstra over the implicit graph, nodes settled in order of (cost, node id). The queue is an
// indexed binary heap of buckets, not of nodes: a bucket is a vertex or one edge's chain of
// Steiner points, keyed by its least unsettled node. A node's cost drops about a hundred times
// before it settles (each settled neighbour across a face offers a better link); in a bucket most
// drops leave its least node alone and cost no heap work, and the heap is an edge count, not a
// node count, deep. Settling a chain's least node rescans the chain. Cost: IsotropicCost or
// DirectionalCost (a template, so the inner loop has no virtual call). kHeaded: A* (HeadFor),
// ordered by (cost + a lower bound of the cost left, node id); a template too, so a whole field's
// search pays nothing for it.
template <typename Cost, bool kHeaded = false>
class Search {
 public:
  Search(const SteinerGraph& g, const Cost& cost)
      : g_(g),
        costs_(cost),
        mesh_(g.mesh()),
        least_(g.nv() + g.edge_count(), kNoIndex),
        slot_(g.nv() + g.edge_count(), kNoIndex),
        run_lo_(g.edge_count(), kNoIndex),
        run_hi_(g.edge_count(), kNoIndex),
        chain_max_(g.edge_count(), kInf) {
    // A headed search reaches a part of the surface: its Steiner nodes' state is written per edge
    // as the wave first reaches the edge (Touch), so a short path query neither writes nor maps
    // the pages of the rest (on Jacksboro at epsilon 0.01, 25 bytes x 6.7M nodes). A whole search
    // writes it all at once.
    const uint32_t n = kHeaded ? g.nv() : g.node_count();
    cost_.resize(g.node_count());
    label_.resize(g.node_count());
    parent_.resize(g.node_count());
    done_.resize(g.node_count());
    if constexpr (kHeaded) ahead_.resize(g.node_count());
    Reset(0, n);
    if constexpr (kHeaded) touched_.assign(g.edge_count(), 0);
  }

  // Orders the search by cost + a lower bound of the cost left to `goal` (A*) instead of by cost.
  // Every node it settles has its least cost, as with Dijkstra, and those costs are Dijkstra's
  // bit for bit (a node's cost is the least of its settled neighbours' offers, whatever their
  // order); it settles fewer. For a search with targets only: costs away from them stay high.
  void HeadFor(const Goal& goal) {
    static_assert(kHeaded, "a Search<Cost, true> heads for a goal");
    goal_ = goal;
  }

  // The bucket of a node: the vertex itself, or nv + its edge.
  uint32_t BucketOf(uint32_t node) const {
    return node < g_.nv() ? node : g_.nv() + g_.EdgeOfNode(node);
  }
  // The position of a node of `bucket` (no search for its edge, as SteinerGraph::Pos needs).
  Vec PosOf(uint32_t node, uint32_t bucket) const {
    return node < g_.nv() ? mesh_.Position(node) : g_.PosOn(node, bucket - g_.nv());
  }

  void Offer(uint32_t node, uint32_t bucket, double cost, uint32_t label, uint32_t parent) {
    ++relaxations_;
    Improve(node, bucket, cost, label, parent);
  }
  // Offer without the count (RelaxEdge counts its links in bulk).
  void Improve(uint32_t node, uint32_t bucket, double cost, uint32_t label, uint32_t parent) {
    Touch(bucket);
    if (!(cost < cost_[node])) return;
    if constexpr (kHeaded) {
      if (cost_[node] == kInf) ahead_[node] = Ahead(node, bucket);
    }
    cost_[node] = cost;
    label_[node] = label;
    parent_[node] = parent;
    const uint32_t least = least_[bucket];
    if (least == kNoIndex) {
      least_[bucket] = node;
      slot_[bucket] = static_cast<uint32_t>(heap_.size());
      heap_.push_back({Key(node), node, bucket});
      SiftUp(slot_[bucket]);
    } else if (node == least || Less(node, least)) {  // the bucket's key dropped
      least_[bucket] = node;
      heap_[slot_[bucket]] = {Key(node), node, bucket};
      SiftUp(slot_[bucket]);
    }
  }

  void Seed(const Located& p, uint32_t label) {
    const uint32_t parent =
        p.canonical.kind == SurfacePoint::Kind::kVertex ? kFromSourceVertex : kFromSourcePoint;
    ForEachLink(g_, p, [&](uint32_t n, Medium m) {
      Offer(n, BucketOf(n), LinkCost(costs_, m, p.pos, g_.Pos(n)), label, parent);
    });
  }

  // Runs until the heap is empty, the next cost exceeds max_distance, or stop(cost) says so;
  // settled(node) is called after each node is settled.
  template <typename Stop, typename Settled>
  absl::Status Run(const WeightedOptions& options, Stop&& stop, Settled&& settled) {
    uint32_t polls = 0;
    while (!heap_.empty()) {
      const uint32_t bucket = heap_[0].bucket;
      const uint32_t u = heap_[0].node;
      const double d = cost_[u];
      // Headed: the key is at most the cost of any target reached through u.
      const double key = Key(u);
      if (key > options.max_distance || stop(key)) break;
      done_[u] = 1;
      Refill(bucket);
      ++settled_;
      if (++polls == 4096) {
        polls = 0;
        if (options.cancel != nullptr && options.cancel->IsCancelled()) {
          return absl::CancelledError("weighted solve cancelled");
        }
        if (absl::Status s = CheckBudget(options.max_windows); !s.ok()) return s;
      }
      Settle(u, bucket, d);
      settled(u);
    }
    peak_heap_ = std::max<uint64_t>(peak_heap_, heap_.capacity());
    return absl::OkStatus();
  }

  // The work budget (WeightedOptions::max_windows, 0: none), spent in links relaxed.
  absl::Status CheckBudget(uint64_t max_windows) const {
    if (max_windows == 0 || relaxations_ / kGraphLinksPerWindow <= max_windows) {
      return absl::OkStatus();
    }
    return LimitExceededError(
        Limit::kWindows,
        absl::StrFormat("work budget exceeded: the travel graph's search relaxed %d links, more "
                        "than the budget of %d windows allows (%d links a window); use a larger "
                        "budget, a larger epsilon or a max_distance",
                        relaxations_, max_windows, kGraphLinksPerWindow));
  }

  // Checks the search's result: no link from a settled node lowers any node's cost. Run after
  // the search (it relaxes every settled node's links again, as if unsettled, and compares).
  absl::Status CheckOptimality() {
    const std::vector<double> settled_cost(cost_.begin(), cost_.end());
    std::vector<uint32_t> settled;
    for (uint32_t n = 0; n < done_.size(); ++n) {
      if (done_[n]) settled.push_back(n);
    }
    std::fill(done_.begin(), done_.end(), 0);
    std::fill(run_lo_.begin(), run_lo_.end(), kNoIndex);
    checking_ = true;  // every link is evaluated, the lower-bound skip too is under test
    for (const uint32_t u : settled) Settle(u, BucketOf(u), settled_cost[u]);
    checking_ = false;
    for (uint32_t n = 0; n < cost_.size(); ++n) {
      if (cost_[n] < settled_cost[n]) {
        return absl::InternalError(
            absl::StrFormat("weighted search: node %d costs %.17g, a link offers %.17g", n,
                            settled_cost[n], cost_[n]));
      }
    }
    return absl::OkStatus();
  }

  // (A node of an edge the wave never reached: +inf, no label or parent.)
  double cost(uint32_t n) const { return Reached(n) ? cost_[n] : kInf; }
  uint32_t label(uint32_t n) const { return Reached(n) ? label_[n] : kNoIndex; }
  uint32_t parent(uint32_t n) const { return Reached(n) ? parent_[n] : kNoIndex; }
  // Nodes beyond max_distance (offered but not settled) become unreachable.
  void ClampTo(double max_distance) {
    for (size_t n = 0; n < cost_.size(); ++n) {
      if (cost_[n] > max_distance) {
        cost_[n] = kInf;
        label_[n] = kNoIndex;
        parent_[n] = kNoIndex;
      }
    }
  }

  WeightedStats Stats(double ms) const {
    WeightedStats s;
    s.nodes_settled = settled_;
    s.edge_relaxations = relaxations_;
    s.peak_bytes = g_.bytes() + cost_.size() * (sizeof(double) + 2 * sizeof(uint32_t) + 1) +
                   (least_.size() + run_lo_.size()) * 2 * sizeof(uint32_t) +
                   (chain_max_.size() + ahead_.size()) * sizeof(double) +
                   peak_heap_ * sizeof(Entry);
    s.solve_ms = ms;
    return s;
  }

 private:
  // Nodes [from, to) as no search has reached them.
  void Reset(uint32_t from, uint32_t to) {
    std::fill(cost_.begin() + from, cost_.begin() + to, kInf);
    std::fill(label_.begin() + from, label_.begin() + to, kNoIndex);
    std::fill(parent_.begin() + from, parent_.begin() + to, kNoIndex);
    std::fill(done_.begin() + from, done_.begin() + to, 0);
    if constexpr (kHeaded) std::fill(ahead_.begin() + from, ahead_.begin() + to, 0.0);
  }
  // Headed: the state of `bucket`'s nodes is written before the search first reads it.
  void Touch(uint32_t bucket) {
    if constexpr (kHeaded) {
      if (bucket < g_.nv()) return;
      const uint32_t e = bucket - g_.nv();
      if (touched_[e]) return;
      touched_[e] = 1;
      Reset(g_.First(e), g_.End(e));
    }
  }
  bool Reached(uint32_t n) const {
    if constexpr (kHeaded) return n < g_.nv() || touched_[g_.EdgeOfNode(n)];
    return true;
  }

  // The queue's order: (key, node id).
  double Key(uint32_t n) const {
    if constexpr (kHeaded) return cost_[n] + ahead_[n];
    return cost_[n];
  }
  bool Less(uint32_t a, uint32_t b) const {
    const double ka = Key(a), kb = Key(b);
    return ka < kb || (ka == kb && a < b);
  }
  // The lower bound of the cost left from node n (of `bucket`) to the goal.
  double Ahead(uint32_t n, uint32_t bucket) const {
    const Vec p = PosOf(n, bucket);
    const double away = Dist(p, goal_.centre) - goal_.radius;
    return away > 0 ? away * goal_.per_metre : 0;
  }
  // A heap entry: a bucket with its least node and that node's key, kept in the entry so that
  // sifting reads the heap alone (no lookups per comparison).
  struct Entry {
    double key;
    uint32_t node, bucket;
  };
  static bool Before(const Entry& a, const Entry& b) {
    return a.key < b.key || (a.key == b.key && a.node < b.node);  // as Less
  }
  void SiftUp(uint32_t i) {
    const Entry x = heap_[i];
    while (i > 0) {
      const uint32_t p = (i - 1) / 2;
      if (!Before(x, heap_[p])) break;
      heap_[i] = heap_[p];
      slot_[heap_[i].bucket] = i;
      i = p;
    }
    heap_[i] = x;
    slot_[x.bucket] = i;
  }
  void SiftDown(uint32_t i) {
    const Entry x = heap_[i];
    const uint32_t size = static_cast<uint32_t>(heap_.size());
    while (true) {
      uint32_t c = 2 * i + 1;
      if (c >= size) break;
      if (c + 1 < size && Before(heap_[c + 1], heap_[c])) ++c;
      if (!Before(heap_[c], x)) break;
      heap_[i] = heap_[c];
      slot_[heap_[i].bucket] = i;
      i = c;
    }
    heap_[i] = x;
    slot_[x.bucket] = i;
  }
  // The top bucket's least node was just settled: its next least unsettled node (with a cost)
  // becomes its key, or the bucket leaves the heap.
  void Refill(uint32_t bucket) {
    uint32_t least = kNoIndex;
    if (bucket >= g_.nv()) {
      const uint32_t e = bucket - g_.nv();
      const uint32_t first = g_.First(e), end = g_.End(e);
      const uint32_t settled = least_[bucket];
      // Grow the edge's settled run by the node just settled (and any settled nodes it joins).
      if (run_lo_[e] == kNoIndex) {
        run_lo_[e] = settled;
        run_hi_[e] = settled + 1;
      } else if (settled == run_hi_[e]) {
        ++run_hi_[e];
      } else if (settled + 1 == run_lo_[e]) {
        --run_lo_[e];
      }
      while (run_hi_[e] < end && done_[run_hi_[e]]) ++run_hi_[e];
      while (run_lo_[e] > first && done_[run_lo_[e] - 1]) --run_lo_[e];
      double best = kInf, most = 0;
      auto scan = [&](uint32_t from, uint32_t to) {
        for (uint32_t n = from; n < to; ++n) {
          if (done_[n]) continue;
          most = std::max(most, cost_[n]);
          const double key = Key(n);
          if (key < best) {  // (key, id): the first of equal keys wins
            best = key;
            least = n;
          }
        }
      };
      scan(first, run_lo_[e]);
      scan(run_hi_[e], end);
      chain_max_[e] = most;  // costs only drop: it stays an upper bound until the next rescan
    }
    least_[bucket] = least;
    if (least != kNoIndex) {
      heap_[0] = {Key(least), least, bucket};  // (the bucket is the heap's top)
      SiftDown(0);
      return;
    }
    peak_heap_ = std::max<uint64_t>(peak_heap_, heap_.size());
    slot_[bucket] = kNoIndex;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (heap_.empty()) return;
    heap_[0] = last;
    SiftDown(0);
  }

  // Relaxes the Steiner nodes of edge e from point p across face f.
  void RelaxEdge(uint32_t e, const Vec& p, double base, uint32_t f, uint32_t label, uint32_t from) {
    const uint32_t begin = g_.First(e), end = g_.End(e);
    if (begin == end) return;
    const uint32_t bucket = g_.nv() + e;
    Touch(bucket);
    const uint32_t h = g_.EdgeHalf(e);
    const Vec a = mesh_.Position(mesh_.From(h)), b = mesh_.Position(mesh_.To(h));
    const double ax = a[0] - p[0], ay = a[1] - p[1], az = a[2] - p[2];
    const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    // Most links cannot improve their node: skip them on a square-root-free lower bound, length
    // x the face's least cost per metre (slightly loosened, so rounding never skips an
    // improvement; the cost that is offered is computed in full). Settled nodes cost at most
    // `base`, so they fail it too.
    const double floor = costs_.FaceFloor(f);
    if (!checking_ && std::isfinite(chain_max_[e])) {
      // The whole chain: no link is shorter than the distance from p to the edge, so when that
      // costs more than the chain's costliest unsettled node, nothing can improve.
      const double sx = -ax, sy = -ay, sz = -az;  // p - a
      const double along =
          std::clamp((sx * dx + sy * dy + sz * dz) / (dx * dx + dy * dy + dz * dz), 0.0, 1.0);
      const double qx = sx - along * dx, qy = sy - along * dy, qz = sz - along * dz;
      if (base + floor * std::sqrt(qx * qx + qy * qy + qz * qz) * (1 - 1e-9) >= chain_max_[e]) {
        return;
      }
    }
    const double per_metre = checking_ ? kInf : 1 / floor;  // (check: no skips)
    const auto walk = costs_.ForFace(f);
    const double* param = g_.Params(begin);
    const double* cost = cost_.data();
    // The settled run is skipped whole; the nodes on either side are tested.
    const uint32_t run_lo = run_lo_[e] == kNoIndex ? end : run_lo_[e];
    const uint32_t run_hi = run_lo_[e] == kNoIndex ? end : run_hi_[e];
    relaxations_ += (run_lo - begin) + (end - run_hi);
    // In blocks of 64: a branch-free pass marks the candidates, then only they are offered.
    uint32_t count = 0;
    for (uint32_t block = begin; block < end; block += count) {
      if (block == run_lo) block = run_hi;
      if (block >= end) break;
      count = std::min<uint32_t>(64, (block < run_lo ? run_lo : end) - block);
      const double* c = cost + block;
      const double* t = param + (block - begin);
#if defined(GEODEX_AVX2_FILTER)
      uint64_t hits =
          kHasAvx2 ? MarkCandidatesAvx2(c, t, count, base, per_metre, {ax, ay, az}, {dx, dy, dz})
                   : MarkCandidates(c, t, count, base, per_metre, {ax, ay, az}, {dx, dy, dz});
#else
      uint64_t hits = MarkCandidates(c, t, count, base, per_metre, {ax, ay, az}, {dx, dy, dz});
#endif
      while (hits != 0) {
        const uint32_t j = static_cast<uint32_t>(__builtin_ctzll(hits));
        hits &= hits - 1;
        const uint32_t n = block + j;
        if (done_[n]) continue;  // settled (a zero-length link)
        const double x = ax + t[j] * dx, y = ay + t[j] * dy, z = az + t[j] * dz;
        Improve(n, bucket, base + walk(x, y, z), label, from);
      }
    }
  }
  // Relaxes node n (of `bucket`) from p through medium m.
  void RelaxNode(uint32_t n, uint32_t bucket, const Vec& p, double base, Medium m, uint32_t label,
                 uint32_t from) {
    Touch(bucket);
    if (done_[n]) return;
    Offer(n, bucket, base + LinkCost(costs_, m, p, PosOf(n, bucket)), label, from);
  }

  // The wave between two settled neighbours u and v on one edge crosses the segment [u, v]
  // anywhere, not only at its ends: a node x across face f (half-edge h of the edge in f) is
  // offered min over s of (1 - s) T(u) + s T(v) + cost(x - ((1 - s) u + s v)), the cost along the
  // segment taken as linear (the ordered upwind update of Sethian and Vladimirsky, 2003, on the
  // Steiner graph). Crossings between nodes cut the error of a graph path (which must bend at
  // nodes) from first to about second order in the spacing: a few times fewer points for the same
  // error. The offer is not a real path's cost, so it is used only where no bound is claimed (a
  // slope cost); it is clamped to at least T(u) so that costs still settle in order, and A* (whose
  // bound covers links) is off for such costs (GoalOf). The cost is convex in s (a convex face
  // cost along a line, plus a linear term), so a golden-section search finds the minimum.
  void CrossSegments(uint32_t f, uint32_t h, uint32_t u, const Vec& p, double dp,
                     std::array<uint32_t, 2> ends, uint32_t lab) {
    if (checking_) return;
    struct Segment {
      uint32_t v = kNoIndex;
      double dq, rx, ry, rz, r2;
    };
    std::array<Segment, 2> segs;
    int count = 0;
    for (const uint32_t v : ends) {
      if (v == kNoIndex || v == u || !done_[v]) continue;
      const Vec q = PosOf(v, v < g_.nv() ? v : g_.nv() + g_.EdgeOfHalf(h));
      Segment& sg = segs[count];
      sg.rx = q[0] - p[0], sg.ry = q[1] - p[1], sg.rz = q[2] - p[2];
      sg.r2 = sg.rx * sg.rx + sg.ry * sg.ry + sg.rz * sg.rz;
      if (!(sg.r2 > 0)) continue;
      sg.v = v;
      sg.dq = cost_[v];
      ++count;
    }
    if (count == 0) return;
    const auto walk = costs_.ForFace(f);
    const double floor = costs_.FaceFloor(f) * (1 - 1e-9);
    auto cross = [&](const Segment& sg, uint32_t n, uint32_t bucket, double xx, double xy,
                     double xz) {
      // Square-root-free skip: the lower end + floor x the distance to the segment cannot beat
      // the node.
      const double t = std::clamp((xx * sg.rx + xy * sg.ry + xz * sg.rz) / sg.r2, 0.0, 1.0);
      const double ox = xx - t * sg.rx, oy = xy - t * sg.ry, oz = xz - t * sg.rz;
      const double gap = cost_[n] - std::min(dp, sg.dq);
      if (gap * gap <= floor * floor * (ox * ox + oy * oy + oz * oz)) return;
      auto at = [&](double s) {
        return (1 - s) * dp + s * sg.dq + walk(xx - s * sg.rx, xy - s * sg.ry, xz - s * sg.rz);
      };
      // An interior minimum needs the cost falling at s = 0 and rising at s = 1 (convexity);
      // otherwise an end is best, and its link was offered already.
      constexpr double kNudge = 1e-3;
      if (!(at(kNudge) < at(0)) || !(at(1 - kNudge) < at(1))) return;
      // Golden section (the face's cost has kinks: Tobler's peak, the switchback ranges).
      constexpr double kGolden = 0.6180339887498949;
      double a = kNudge, b = 1 - kNudge;
      double c = b - kGolden * (b - a), e = a + kGolden * (b - a);
      double fc = at(c), fe = at(e);
      for (int i = 0; i < 8; ++i) {  // the bracket shrinks to 2% of the segment
        if (fc < fe) {
          b = e, e = c, fe = fc;
          c = b - kGolden * (b - a), fc = at(c);
        } else {
          a = c, c = e, fc = fe;
          e = a + kGolden * (b - a), fe = at(e);
        }
      }
      const double s = fc < fe ? c : e;
      const double cost = std::max(std::min(fc, fe), dp);
      ++relaxations_;
      Improve(n, bucket, cost, s < 0.5 ? lab : label_[sg.v], s < 0.5 ? u : sg.v);
    };
    auto offer = [&](uint32_t n, uint32_t bucket, const Vec& x) {
      if (done_[n] || cost_[n] <= dp) return;  // the clamped offer is at least dp
      // Only a node whose best link is from a segment's end: the wave reaches it across it.
      const uint32_t parent = parent_[n];
      const double xx = x[0] - p[0], xy = x[1] - p[1], xz = x[2] - p[2];
      for (int i = 0; i < count; ++i) {
        if (parent == u || parent == segs[i].v) cross(segs[i], n, bucket, xx, xy, xz);
      }
    };
    const uint32_t nv = g_.nv();
    for (const uint32_t t : {TriangleMesh::Next(h), TriangleMesh::Prev(h)}) {
      const uint32_t e = g_.EdgeOfHalf(t);
      const uint32_t first = g_.First(e), end = g_.End(e);
      if (first == end) continue;
      Touch(nv + e);
      const uint32_t he = g_.EdgeHalf(e);
      const Vec a = mesh_.Position(mesh_.From(he)), b = mesh_.Position(mesh_.To(he));
      const double* param = g_.Params(first);
      for (uint32_t n = first; n < end; ++n) {
        offer(n, nv + e, SteinerGraph::Lerp(a, b, param[n - first]));
      }
    }
    const uint32_t o = mesh_.Opposite(h);
    offer(o, o, mesh_.Position(o));
  }

  void Settle(uint32_t u, uint32_t bucket, double d) {
    const uint32_t nv = g_.nv();
    const Vec p = PosOf(u, bucket);
    const uint32_t lab = label_[u];
    if (u < g_.nv()) {
      for (const uint32_t* c = mesh_.CornersBegin(u); c != mesh_.CornersEnd(u); ++c) {
        // Along the two edges at u: the nearest node.
        const std::array<uint32_t, 2> at_u = {*c, TriangleMesh::Prev(*c)};
        std::array<uint32_t, 2> next = {kNoIndex, kNoIndex};
        for (int i = 0; i < 2; ++i) {
          const uint32_t h = at_u[i], e = g_.EdgeOfHalf(h);
          if (!std::isfinite(g_.EdgeWeight(e))) continue;
          if (g_.First(e) == g_.End(e)) {
            next[i] = mesh_.From(h) == u ? mesh_.To(h) : mesh_.From(h);
          } else {
            next[i] = mesh_.From(g_.EdgeHalf(e)) == u ? g_.First(e) : g_.End(e) - 1;
          }
          RelaxNode(next[i], next[i] < nv ? next[i] : nv + e, p, d, Medium{Medium::kEdge, e}, lab,
                    u);
        }
        // Across the face: the opposite edge's Steiner points.
        const uint32_t f = TriangleMesh::FaceOf(*c);
        if (std::isfinite(g_.FaceWeight(f))) {
          RelaxEdge(g_.EdgeOfHalf(TriangleMesh::Next(*c)), p, d, f, lab, u);
          if constexpr (Cost::kInterpolates) {
            // The segments from u to those nearest nodes (the face is passable, so both edges are).
            for (int i = 0; i < 2; ++i)
              CrossSegments(f, at_u[i], u, p, d, {next[i], kNoIndex}, lab);
          }
        }
      }
      return;
    }
    const uint32_t e = bucket - nv;
    const uint32_t h0 = g_.EdgeHalf(e);
    // u's neighbours along its edge: the previous and next Steiner nodes, or the edge's ends.
    const uint32_t before = u == g_.First(e) ? mesh_.From(h0) : u - 1;
    const uint32_t after = u + 1 == g_.End(e) ? mesh_.To(h0) : u + 1;
    if (std::isfinite(g_.EdgeWeight(e))) {  // (a Steiner node's edge has a passable face)
      const Medium along{Medium::kEdge, e};
      RelaxNode(before, before < nv ? before : bucket, p, d, along, lab, u);
      RelaxNode(after, after < nv ? after : bucket, p, d, along, lab, u);
    }
    for (const uint32_t h : {h0, mesh_.Twin(h0)}) {
      if (h == kNoIndex) continue;
      const uint32_t f = TriangleMesh::FaceOf(h);
      if (!std::isfinite(g_.FaceWeight(f))) continue;
      RelaxEdge(g_.EdgeOfHalf(TriangleMesh::Next(h)), p, d, f, lab, u);
      RelaxEdge(g_.EdgeOfHalf(TriangleMesh::Prev(h)), p, d, f, lab, u);
      if constexpr (Cost::kInterpolates) CrossSegments(f, h, u, p, d, {before, after}, lab);
      const uint32_t o = mesh_.Opposite(h);
      RelaxNode(o, o, p, d, Medium{Medium::kFace, f}, lab, u);
    }
  }

  const SteinerGraph& g_;
  const Cost& costs_;
  const TriangleMesh& mesh_;
  LazyVector<double> cost_;
  LazyVector<uint32_t> label_, parent_;
  LazyVector<uint8_t> done_;            // per node: settled
  std::vector<uint8_t> touched_;        // headed, per edge: its nodes' state is written (Touch)
  std::vector<uint32_t> least_, slot_;  // per bucket: least unsettled node, heap position
  // Per edge: a run [lo, hi) of its settled Steiner nodes, the first one settled and those that
  // joined it (on an edge the wave mostly settles outward from where it arrived); relaxations and
  // rescans skip it.
  std::vector<uint32_t> run_lo_, run_hi_;
  // Per edge: at least the cost of its costliest unsettled node (+inf until the edge's first
  // rescan, or while one is unreached); a relaxation that cannot beat it skips the chain.
  std::vector<double> chain_max_;
  bool checking_ = false;  // CheckOptimality is running
  Goal goal_;
  LazyVector<double> ahead_;  // headed: per node reached, Ahead(node)
  std::vector<Entry> heap_;   // buckets
  uint64_t settled_ = 0, relaxations_ = 0, peak_heap_ = 0;
};

// The best (cost, node) over the links of point t; node kNoIndex when the best is none.
template <typename Cost, bool kHeaded>
std::pair<double, uint32_t> BestLink(const SteinerGraph& g, const Cost& cost,
                                     const Search<Cost, kHeaded>& search, const Located& t) {
  double best = kInf;
  uint32_t node = kNoIndex;
  ForEachLink(g, t, [&](uint32_t n, Medium m) {
    const double c = search.cost(n);
    if (!std::isfinite(c)) return;
    const double total = c + LinkCost(cost, m, g.Pos(n), t.pos);
    if (total < best || (total == best && n < node)) {
      best = total;
      node = n;
    }
  });
  return {best, node};
}

// The goal of a search towards `to`: the ball around the targets' bounding box and the least
// cost per metre of any link (every passable face's floor; an edge link costs what one of its
// faces would), shaved so that rounding never makes the bound exceed a true cost.
template <typename Cost>
Goal GoalOf(const SteinerGraph& g, const Cost& cost, const std::vector<Located>& to) {
  Goal goal;
  // A segment's offer (Search::CrossSegments) is below its ends' links, outside what the bound
  // covers: such a search runs as Dijkstra (a zero bound) and still stops once its targets are
  // final, so its answers stay the whole search's bit for bit.
  if constexpr (Cost::kInterpolates) return goal;
  if (to.empty()) return goal;
  Vec lo = to[0].pos, hi = to[0].pos;
  for (const Located& t : to) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], t.pos[k]);
      hi[k] = std::max(hi[k], t.pos[k]);
    }
  }
  for (int k = 0; k < 3; ++k) goal.centre[k] = (lo[k] + hi[k]) / 2;
  for (const Located& t : to) goal.radius = std::max(goal.radius, Dist(t.pos, goal.centre));
  double floor = kInf;
  for (uint32_t f = 0; f < g.mesh().face_count(); ++f) {
    if (std::isfinite(g.FaceWeight(f))) floor = std::min(floor, cost.FaceFloor(f));
  }
  goal.per_metre = std::isfinite(floor) ? floor * (1 - 1e-9) : 0;
  return goal;
}

// Targets watched during a search, so that it can stop once each is final: per target its best
// cost so far, straight from a source or through a settled node linked to it. Once the next
// cost to settle exceeds every best, no link can lower one (an unsettled node costs at least
// that). The stop is strict, so every node a best could come through is settled, as in a whole
// search: the answers are the whole search's bit for bit.
template <typename Cost>
class TargetWatch {
 public:
  TargetWatch(const SteinerGraph& g, const Cost& cost, const std::vector<Located>& from,
              const std::vector<Located>& to)
      : g_(g), cost_(cost), to_(to), best_(to.size(), kInf) {
    for (uint32_t t = 0; t < to.size(); ++t) {
      ForEachLink(g, to[t], [&](uint32_t n, Medium m) { links_.push_back({n, t, m}); });
      for (const Located& s : from) best_[t] = std::min(best_[t], DirectCost(g, cost, s, to[t]));
    }
    std::stable_sort(links_.begin(), links_.end(),
                     [](const Link& a, const Link& b) { return a.node < b.node; });
    Rebound();
  }
  // True once a node settling at `key` can improve no target.
  bool Done(double key) {
    if (!(key > worst_)) return false;
    Rebound();  // worst_ was an upper bound (bests only drop): make it exact
    return key > worst_;
  }
  void Settled(uint32_t u, double cost_u) {
    auto it = std::lower_bound(links_.begin(), links_.end(), u,
                               [](const Link& l, uint32_t n) { return l.node < n; });
    for (; it != links_.end() && it->node == u; ++it) {
      const double c = cost_u + LinkCost(cost_, it->medium, g_.Pos(u), to_[it->target].pos);
      double& best = best_[it->target];
      if (!(c < best)) continue;
      const bool last = best == kInf && --unreached_ == 0;
      best = c;
      if (last) Rebound();  // every target has a best: worst_ becomes finite
    }
  }

 private:
  struct Link {
    uint32_t node, target;
    Medium medium;
  };
  void Rebound() {
    worst_ = -kInf;
    unreached_ = 0;
    for (const double b : best_) {
      worst_ = std::max(worst_, b);
      unreached_ += b == kInf;
    }
  }

  const SteinerGraph& g_;
  const Cost& cost_;
  const std::vector<Located>& to_;
  std::vector<Link> links_;  // what the straight link from each node to each target runs in
  std::vector<double> best_;
  double worst_ = kInf;     // at least the largest best
  uint32_t unreached_ = 0;  // targets with no best yet (worst_ is +inf while there are)
};

// Seeds every source (its label: its index) and searches to the end, or to max_distance (costs
// beyond it become unreachable): what a field and point costs need.
template <typename Cost>
absl::Status SearchWhole(const std::vector<Located>& sources, const WeightedOptions& options,
                         Search<Cost>* search) {
  for (uint32_t i = 0; i < sources.size(); ++i) search->Seed(sources[i], i);
  absl::Status status = search->Run(
      options, [](double) { return false; }, [](uint32_t) {});
  if (status.ok() && options.check_optimality) status = search->CheckOptimality();
  if (status.ok()) search->ClampTo(options.max_distance);
  return status;
}

}  // namespace geodex::weighted_internal
