#pragma once

// A fixed set of worker threads with a bounded queue: all geometry runs here, never on gRPC's
// threads. TrySubmit refuses work at once when the queue is full (the caller answers
// RESOURCE_EXHAUSTED) instead of letting requests pile up.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"

namespace geodex::server {

class ComputePool {
 public:
  // `threads` workers (>= 1); at most `queue_capacity` tasks wait while all workers are busy.
  ComputePool(size_t threads, size_t queue_capacity);
  // Runs every queued task, then joins the workers.
  ~ComputePool();

  ComputePool(const ComputePool&) = delete;
  ComputePool& operator=(const ComputePool&) = delete;

  // Queues `task`; false (task dropped) when the queue is full or the pool is shutting down.
  bool TrySubmit(std::function<void()> task);

  size_t threads() const { return workers_.size(); }
  size_t queue_capacity() const { return queue_capacity_; }
  size_t queued() const;
  size_t busy() const;
  uint64_t rejected() const;

 private:
  void WorkerLoop();

  const size_t queue_capacity_;
  mutable absl::Mutex mu_;
  std::deque<std::function<void()>> queue_ ABSL_GUARDED_BY(mu_);
  size_t busy_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t rejected_ ABSL_GUARDED_BY(mu_) = 0;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::vector<std::thread> workers_;
};

}  // namespace geodex::server
