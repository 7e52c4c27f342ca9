#pragma once

// A fixed set of worker threads with a bounded queue: all geometry runs here, never on gRPC's
// threads. TrySubmit refuses work at once when the queue is full (the caller answers
// RESOURCE_EXHAUSTED) instead of letting requests pile up.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

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

  // Orders everything this thread wrote before the call before every task a worker runs afterwards
  // (a release of the queue's mutex). geodexd calls it once the service exists: the workers were
  // started before it, and gRPC's own hand-off of calls is invisible to ThreadSanitizer.
  void Publish();

  // Called by a running task just before it hands its result to gRPC (Finish or a first write).
  // It frees the task's place in the busy count at once: the client's next call may arrive before
  // this thread returns from the task, and must not be refused for a place whose work is done.
  // A no-op outside a task, and after the first call within one.
  void ReleaseWorker();

  size_t threads() const { return workers_.size(); }
  size_t queue_capacity() const { return queue_capacity_; }
  size_t queued() const;
  size_t busy() const;
  uint64_t rejected() const;

 private:
  void WorkerLoop();

  const size_t queue_capacity_;
  // std::mutex rather than absl::Mutex: Debian's Abseil is not built for ThreadSanitizer, so its
  // mutexes would be invisible to the sanitizer tier.
  mutable std::mutex mu_;
  std::condition_variable work_;             // a task arrived, or stopping
  std::deque<std::function<void()>> queue_;  // guarded by mu_
  size_t busy_ = 0;                          // guarded by mu_
  uint64_t rejected_ = 0;                    // guarded by mu_
  bool stopping_ = false;                    // guarded by mu_
  std::vector<std::thread> workers_;
};

}  // namespace geodex::server
