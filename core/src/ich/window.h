#pragma once

// The engine's private window types: the sequence tree lives in one flat pool, linked by index.

#include <cstdint>
#include <vector>

#include "geodex/triangle_mesh.h"

namespace geodex::ich {

enum class WindowKind : uint8_t { kInterval, kPseudoSource };
// Which child of its parent an interval window is: the one on the edge from the parent edge's
// start to the opposite vertex (left), from the opposite vertex to the parent edge's end (right),
// or one of the windows a pseudo-source spawns on its opposite edges (initial).
enum class WindowSide : uint8_t { kInitial, kLeft, kRight };
enum class WindowState : uint8_t { kQueued, kProcessed, kFree };

// One window. Interval windows lie on half-edge `element` and propagate into its face; the
// interval [b0, b1] is measured from the half-edge's start and (ix, iy), iy < 0, is the unfolded
// image of the pseudo-source in the half-edge's frame. Pseudo-source windows sit at vertex
// `element` with sigma = its distance.
struct Window {
  double b0, b1;
  double ix, iy;
  double sigma;
  uint32_t element;
  uint32_t parent;
  uint32_t first_child;
  uint32_t prev_sibling, next_sibling;
  uint32_t pseudo_source;  // vertex the paths bend at last (kNoIndex: the source point itself)
  uint32_t source;         // label: index into the solve's source list
  uint32_t level;
  uint32_t generation;     // bumped on free, so stale queue entries and owner records are detected
  WindowKind kind;
  WindowSide side;
  WindowState state;
};

// A pool of windows with a free list: no heap allocation per window once the pool has grown.
class WindowPool {
 public:
  uint32_t Allocate() {
    uint32_t id;
    if (!free_.empty()) {
      id = free_.back();
      free_.pop_back();
    } else {
      id = static_cast<uint32_t>(windows_.size());
      windows_.emplace_back();
      windows_.back().generation = 0;
    }
    Window& w = windows_[id];
    w.parent = w.first_child = w.prev_sibling = w.next_sibling = kNoIndex;
    w.state = WindowState::kQueued;
    ++live_;
    if (live_ > peak_live_) peak_live_ = live_;
    return id;
  }
  void Free(uint32_t id) {
    Window& w = windows_[id];
    w.state = WindowState::kFree;
    ++w.generation;
    free_.push_back(id);
    --live_;
  }
  Window& operator[](uint32_t id) { return windows_[id]; }
  const Window& operator[](uint32_t id) const { return windows_[id]; }

  // Tree links (doubly linked sibling lists: unlinking is O(1) even under a pseudo-source).
  void AddChild(uint32_t parent, uint32_t child) {
    Window& c = windows_[child];
    Window& p = windows_[parent];
    c.parent = parent;
    c.prev_sibling = kNoIndex;
    c.next_sibling = p.first_child;
    if (p.first_child != kNoIndex) windows_[p.first_child].prev_sibling = child;
    p.first_child = child;
  }
  void Unlink(uint32_t child) {
    Window& c = windows_[child];
    if (c.parent == kNoIndex) return;
    if (c.prev_sibling != kNoIndex) {
      windows_[c.prev_sibling].next_sibling = c.next_sibling;
    } else {
      windows_[c.parent].first_child = c.next_sibling;
    }
    if (c.next_sibling != kNoIndex) windows_[c.next_sibling].prev_sibling = c.prev_sibling;
    c.parent = c.prev_sibling = c.next_sibling = kNoIndex;
  }

  uint64_t live() const { return live_; }
  uint64_t peak_live() const { return peak_live_; }
  uint64_t CapacityBytes() const {
    return windows_.capacity() * sizeof(Window) + free_.capacity() * sizeof(uint32_t);
  }

 private:
  std::vector<Window> windows_;
  std::vector<uint32_t> free_;
  uint64_t live_ = 0, peak_live_ = 0;
};

// Priority queue entry: windows are processed by the smallest distance they can give.
struct QueueEntry {
  double key;
  uint32_t window;
  uint32_t generation;
};

// A 4-ary min-heap of queue entries: half the depth of a binary heap, and the four children of a
// node share a cache line, which matters with millions of windows in flight.
class WindowQueue {
 public:
  bool empty() const { return heap_.empty(); }
  void clear() { heap_.clear(); }
  void reserve(size_t n) { heap_.reserve(n); }
  uint64_t CapacityBytes() const { return heap_.capacity() * sizeof(QueueEntry); }

  void Push(const QueueEntry& e) {
    size_t i = heap_.size();
    heap_.push_back(e);
    while (i > 0) {
      const size_t parent = (i - 1) / 4;
      if (!Less(e, heap_[parent])) break;
      heap_[i] = heap_[parent];
      i = parent;
    }
    heap_[i] = e;
  }

  QueueEntry Pop() {
    const QueueEntry top = heap_.front();
    const QueueEntry last = heap_.back();
    heap_.pop_back();
    const size_t n = heap_.size();
    if (n == 0) return top;
    size_t i = 0;
    for (;;) {
      const size_t first = 4 * i + 1;
      if (first >= n) break;
      size_t best = first;
      const size_t end = first + 4 < n ? first + 4 : n;
      for (size_t c = first + 1; c < end; ++c) {
        if (Less(heap_[c], heap_[best])) best = c;
      }
      if (!Less(heap_[best], last)) break;
      heap_[i] = heap_[best];
      i = best;
    }
    heap_[i] = last;
    return top;
  }

 private:
  // Smallest key first; ties broken by window id so runs are deterministic.
  static bool Less(const QueueEntry& a, const QueueEntry& b) {
    return a.key != b.key ? a.key < b.key : a.window < b.window;
  }
  std::vector<QueueEntry> heap_;
};

// Lemma 1 bookkeeping per half-edge: the window on it that gave its opposite vertex the smallest
// distance, where its ray to that vertex crosses the edge, and that distance.
struct SplitOwner {
  uint32_t window = kNoIndex;
  uint32_t generation = 0;
  double distance = 0;  // meaningful only when window != kNoIndex
  double cross_x = 0;
};

}  // namespace geodex::ich
