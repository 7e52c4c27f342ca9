#pragma once

// The engine's private window types: the sequence tree lives in one flat pool, linked by index.

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <new>
#include <vector>

#include "geodex/triangle_mesh.h"

namespace geodex::ich {

// Allocates large arrays on 2 MiB boundaries and asks for transparent huge pages: the engine's
// arrays are read at random, and with 4 KiB pages most of those reads also miss the TLB.
template <typename T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(size_t n) {
    constexpr size_t kHuge = size_t{1} << 21;
    const size_t bytes = n * sizeof(T);
    if (bytes < kHuge) return std::allocator<T>().allocate(n);
    const size_t rounded = (bytes + kHuge - 1) & ~(kHuge - 1);
    void* p = std::aligned_alloc(kHuge, rounded);
    if (p == nullptr) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    madvise(p, rounded, MADV_HUGEPAGE);
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) {
    if (n * sizeof(T) < (size_t{1} << 21)) {
      std::allocator<T>().deallocate(p, n);
    } else {
      std::free(p);
    }
  }
  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
};
template <typename T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

// kBoundaryPoint: a point on an edge between two regions of a weighted surface (region_links.h),
// made only while it emits (the point itself is queued, not this window); `element` is its index.
enum class WindowKind : uint8_t { kInterval, kPseudoSource, kBoundaryPoint };
// Which child of its parent an interval window is: the one on the edge from the parent edge's
// start to the opposite vertex (left), from the opposite vertex to the parent edge's end (right),
// or one of the windows a pseudo-source spawns on its opposite edges (initial).
enum class WindowSide : uint8_t { kInitial, kLeft, kRight };
enum class WindowState : uint8_t { kQueued, kProcessed, kFree };

// One window. Interval windows lie on half-edge `element` and propagate into its face; the
// interval [b0, b1] is measured from the half-edge's start and (ix, iy), iy < 0, is the unfolded
// image of the pseudo-source in the half-edge's frame. Pseudo-source windows sit at vertex
// `element` with sigma = its distance.
//
// Split in two arrays: the geometry processing reads (exactly one cache line) and the tree links
// the bookkeeping walks (24 bytes), so parent-chain walks and stale checks touch small records.
struct alignas(64) Window {
  double b0, b1;
  double ix, iy;
  double sigma;
  uint32_t element;
  uint32_t pseudo_source;  // vertex the paths bend at last (kNoIndex: the source point itself)
  uint32_t source;         // label: index into the solve's source list
  uint32_t level;
  WindowKind kind;
  WindowSide side;
};

struct WindowLinks {
  uint32_t parent;
  uint32_t first_child;
  uint32_t prev_sibling, next_sibling;
  uint32_t generation;  // bumped on free, so stale queue entries and owner records are detected
  WindowKind kind;      // copies of the window's (fixed once made), for tree walks
  WindowSide side;
  WindowState state;
};

// A pool of windows with a free list: no heap allocation per window once the pool has grown.
// Links (parents, children, generations, states) are kept only for the paper's window tree
// (`with_links`); without them a window is just its geometry, freed right after processing.
class WindowPool {
 public:
  explicit WindowPool(bool with_links = false) : with_links_(with_links) {}

  // Empties the pool for a new solve, keeping its capacity.
  void Reset(bool with_links) {
    with_links_ = with_links;
    windows_.clear();
    links_.clear();
    free_.clear();
    live_ = peak_live_ = 0;
  }
  // Returns the pool's memory (after a solve that needed far more windows than the next may).
  void ReleaseMemory() {
    HugeVector<Window>().swap(windows_);
    HugeVector<WindowLinks>().swap(links_);
    std::vector<uint32_t>().swap(free_);
  }

  uint32_t Allocate() {
    uint32_t id;
    if (!free_.empty()) {
      id = free_.back();
      free_.pop_back();
    } else {
      id = static_cast<uint32_t>(windows_.size());
      windows_.emplace_back();
      if (with_links_) {
        links_.emplace_back();
        links_.back().generation = 0;
      }
    }
    ++live_;
    if (live_ > peak_live_) peak_live_ = live_;
    if (!with_links_) return id;
    WindowLinks& l = links_[id];
    l.parent = l.first_child = l.prev_sibling = l.next_sibling = kNoIndex;
    l.state = WindowState::kQueued;
    return id;
  }
  // Records kind and side (call once the window's fields are set).
  void SetKind(uint32_t id, WindowKind kind, WindowSide side) {
    windows_[id].kind = kind;
    windows_[id].side = side;
    if (!with_links_) return;
    links_[id].kind = kind;
    links_[id].side = side;
  }
  void Free(uint32_t id) {
    if (with_links_) {
      WindowLinks& l = links_[id];
      l.state = WindowState::kFree;
      ++l.generation;
    }
    free_.push_back(id);
    --live_;
  }
  bool with_links() const { return with_links_; }
  // Without links these are no-ops (generation 0, never stale): no window is ever deleted while
  // queued, and nothing refers to a processed one.
  uint32_t generation(uint32_t id) const { return with_links_ ? links_[id].generation : 0; }
  void MarkProcessed(uint32_t id) {
    if (with_links_) links_[id].state = WindowState::kProcessed;
  }
  // A queue entry made at `generation` no longer names a queued window (deleted or recycled).
  bool IsStale(uint32_t id, uint32_t generation) const {
    return with_links_ &&
           (links_[id].generation != generation || links_[id].state != WindowState::kQueued);
  }
  Window& operator[](uint32_t id) { return windows_[id]; }
  const Window& operator[](uint32_t id) const { return windows_[id]; }
  WindowLinks& links(uint32_t id) { return links_[id]; }
  const WindowLinks& links(uint32_t id) const { return links_[id]; }
  void PrefetchLinks(uint32_t id) const { __builtin_prefetch(&links_[id]); }
  void Prefetch(uint32_t id) const {
    __builtin_prefetch(&windows_[id]);
    if (with_links_) __builtin_prefetch(&links_[id]);
  }

  // Tree links (doubly linked sibling lists: unlinking is O(1) even under a pseudo-source).
  void AddChild(uint32_t parent, uint32_t child) {
    if (!with_links_) return;
    WindowLinks& c = links_[child];
    WindowLinks& p = links_[parent];
    c.parent = parent;
    c.prev_sibling = kNoIndex;
    c.next_sibling = p.first_child;
    if (p.first_child != kNoIndex) links_[p.first_child].prev_sibling = child;
    p.first_child = child;
  }
  void Unlink(uint32_t child) {
    WindowLinks& c = links_[child];
    if (c.parent == kNoIndex) return;
    if (c.prev_sibling != kNoIndex) {
      links_[c.prev_sibling].next_sibling = c.next_sibling;
    } else {
      links_[c.parent].first_child = c.next_sibling;
    }
    if (c.next_sibling != kNoIndex) links_[c.next_sibling].prev_sibling = c.prev_sibling;
    c.parent = c.prev_sibling = c.next_sibling = kNoIndex;
  }

  uint64_t live() const { return live_; }
  uint64_t ids_issued() const { return windows_.size(); }  // every id so far is below this
  uint64_t peak_live() const { return peak_live_; }
  uint64_t CapacityBytes() const {
    return windows_.capacity() * sizeof(Window) + links_.capacity() * sizeof(WindowLinks) +
           free_.capacity() * sizeof(uint32_t);
  }

 private:
  bool with_links_;
  HugeVector<Window> windows_;
  HugeVector<WindowLinks> links_;
  std::vector<uint32_t> free_;
  uint64_t live_ = 0, peak_live_ = 0;
};

// Priority queue entry: windows are processed by the smallest distance they can give.
struct QueueEntry {
  double key;
  uint32_t window;
  uint32_t generation;
};

// A monotone radix heap of queue entries on quantised keys: a key (a distance, >= 0) counts as
// floor(key / resolution), with the resolution a fraction of the mesh's mean edge length, and
// entries of equal quantised keys pop in LIFO order. Bucket i > 0 holds quantised keys whose
// highest bit differing from the last popped one is bit i-1; bucket 0 holds those equal to it.
// Pops empty a bucket at a time into smaller ones, so entries move a few times through sequential
// arrays instead of sifting through a tree of cache misses and mispredicted compares; quantising
// makes those moves rarer and keeps bucket 0 full, so the next window is known (and prefetched)
// while this one is processed.
//
// Order only steers efficiency: every rule that drops a window compares against current vertex
// distances, which are always upper bounds, so processing near-ties in any order (or a push below
// the last popped key, from round-off: it is queued at that key) costs nothing in exactness. Too
// coarse an order does cost work (windows pass on distances that are later improved): half an
// edge keeps the window count within 0.3% of exact order on the benchmark meshes (two edges add
// 12-20%). What needs a true bound of every queued key (early stops) uses LowerBound(). Runs
// are deterministic.
class WindowQueue {
 public:
  bool empty() const { return size_ == 0; }
  // Empties the queue; keys are then quantised at `resolution` (> 0).
  void Reset(double resolution) {
    for (auto& b : buckets_) b.clear();
    size_ = 0;
    last_ = 0;
    if (!(resolution > 0 && resolution < 1e300)) resolution = 1;
    resolution_ = resolution;
    inverse_ = 1 / resolution;
  }
  void reserve(size_t n) { buckets_[0].reserve(n / 8); }
  void ReleaseMemory() {
    for (auto& b : buckets_) std::vector<QueueEntry>().swap(b);
    size_ = 0;
  }
  uint64_t CapacityBytes() const {
    uint64_t bytes = 0;
    for (const auto& b : buckets_) bytes += b.capacity() * sizeof(QueueEntry);
    return bytes;
  }

  // The quantised key an entry pushed now with `key` is popped at (keys below the bucket being
  // popped are queued at it). Two entries of one slot pop in either order.
  uint64_t SlotOf(double key) const { return std::max(Quantise(key), last_); }

  void Push(QueueEntry e) {
    uint64_t q = Quantise(e.key);
    if (q < last_) {
      q = last_;
      e.key = std::max(e.key, LowerBound());
    }
    buckets_[BucketOf(q)].push_back(e);
    ++size_;
  }

  // The entry Pop() would return next, if it is already known without reorganising the buckets
  // (for prefetching). Refilling here would advance the lower bound past keys the current window's
  // children may still need, and those would be queued late with overstated keys.
  const QueueEntry* Peek() const { return buckets_[0].empty() ? nullptr : &buckets_[0].back(); }

  QueueEntry Pop() {
    Refill();
    const QueueEntry top = buckets_[0].back();
    buckets_[0].pop_back();
    --size_;
    return top;
  }

  // No queued key is below this (the bucket being popped, less the round-off of quantising).
  double LowerBound() const {
    return static_cast<double>(last_) * resolution_ *
           (1 - 4 * std::numeric_limits<double>::epsilon());
  }

 private:
  uint64_t Quantise(double key) const {
    double q = key * inverse_;
    if (!(q < 1.8e19)) q = 1.8e19;  // also NaN: never UB in the conversion
    return static_cast<uint64_t>(q);
  }
  size_t BucketOf(uint64_t q) const {
    return q == last_ ? 0 : 64 - static_cast<size_t>(__builtin_clzll(q ^ last_));
  }
  // Makes bucket 0 non-empty: the smallest non-empty bucket's minimum becomes the last key and the
  // bucket's entries move down.
  void Refill() {
    if (!buckets_[0].empty()) return;
    size_t i = 1;
    while (buckets_[i].empty()) ++i;
    std::vector<QueueEntry>& from = buckets_[i];
    uint64_t lowest = Quantise(from[0].key);
    for (const QueueEntry& e : from) lowest = std::min(lowest, Quantise(e.key));
    last_ = lowest;
    for (const QueueEntry& e : from) buckets_[BucketOf(Quantise(e.key))].push_back(e);
    from.clear();
  }

  std::vector<QueueEntry> buckets_[65];
  uint64_t last_ = 0;  // the quantised key of the bucket being popped
  size_t size_ = 0;
  double resolution_ = 1, inverse_ = 1;
};

// Lemma 1 bookkeeping per half-edge: the smallest distance a window on it gave its opposite
// vertex (+inf: none yet), and where that window's ray to the vertex crosses the edge.
struct SplitRecord {
  double distance = std::numeric_limits<double>::infinity();
  double cross_x = 0;
};
// The paper's ICH (window tree) also remembers which window that was, to delete a subtree of it
// when a better one arrives.
struct SplitOwner {
  uint32_t window = kNoIndex;
  uint32_t generation = 0;
};

}  // namespace geodex::ich
