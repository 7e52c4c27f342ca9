#pragma once

// Background promotion of hot path sources to cached fields, off every caller's clock.
//
// A path query runs A* (or traces a field already cached): its latency is that of the work it
// asked for. When a source is asked for paths again (FieldCache::NotePathSource), its whole field
// is offered here and solved on one background thread at the lowest CPU priority, with a cancel
// token and a window budget of its own, then put in the result cache, so later paths from that
// source are traces. A caller's deadline or cancellation never wastes it, and no caller waits for
// it. Bounded: one solve at a time, at most `capacity` waiting (more offers are dropped and
// counted), each at most the cache's budget once made. Counted in ServiceCounters
// (background_solves, background_dropped; geodexd's /metrics). Thread-safe.

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/container/flat_hash_set.h"
#include "field_cache.h"
#include "geodex/cancel.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "mesh_store.h"
#include "queries.h"

namespace geodex::server {

class FieldPromoter {
 public:
  // `cache` and `counters` outlive it; `max_windows` bounds each solve (0: none).
  FieldPromoter(FieldCache* cache, ServiceCounters* counters, uint64_t max_windows,
                size_t capacity = 8);
  ~FieldPromoter();  // Stop()
  FieldPromoter(const FieldPromoter&) = delete;
  FieldPromoter& operator=(const FieldPromoter&) = delete;

  // Queues the field of `sources` on `mesh` under the cache key `key`, unless it is queued or
  // being solved already, the queue is full (dropped) or the promoter stopped. Returns at once.
  void Offer(std::shared_ptr<const StoredMesh> mesh, std::vector<SurfacePoint> sources,
             GeodesicOptions options, std::string key);
  // Cancels the running solve, drops the queue and joins the thread; later offers are dropped.
  void Stop();

 private:
  struct Job {
    std::shared_ptr<const StoredMesh> mesh;
    std::vector<SurfacePoint> sources;
    GeodesicOptions options;
    std::string key;
  };
  void Run();

  FieldCache* const cache_;
  ServiceCounters* const counters_;
  const uint64_t max_windows_;
  const size_t capacity_;
  CancelToken cancel_;
  std::mutex mu_;
  std::condition_variable wake_;
  std::deque<Job> queue_;                     // guarded by mu_
  absl::flat_hash_set<std::string> pending_;  // queued or running keys; guarded by mu_
  bool stopped_ = false;                      // guarded by mu_
  std::thread thread_;
};

}  // namespace geodex::server
