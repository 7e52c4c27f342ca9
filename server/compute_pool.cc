#include "compute_pool.h"

#include <utility>

namespace geodex::server {

ComputePool::ComputePool(size_t threads, size_t queue_capacity) : queue_capacity_(queue_capacity) {
  if (threads == 0) threads = 1;
  workers_.reserve(threads);
  for (size_t i = 0; i < threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

ComputePool::~ComputePool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  work_.notify_all();
  for (std::thread& t : workers_) t.join();
}

bool ComputePool::TrySubmit(std::function<void()> task) {
  std::unique_lock<std::mutex> lock(mu_);
  // A task may start at once only if a worker is idle; otherwise it waits in the queue.
  size_t idle = workers_.size() - busy_;
  size_t waiting_after = queue_.size() + 1 > idle ? queue_.size() + 1 - idle : 0;
  if (stopping_ || waiting_after > queue_capacity_) {
    ++rejected_;
    return false;
  }
  queue_.push_back(std::move(task));
  lock.unlock();
  work_.notify_one();
  return true;
}

namespace {
// Whether the task running on this worker thread already gave back its place (ReleaseWorker).
thread_local bool t_in_task = false;
thread_local bool t_released = false;
}  // namespace

void ComputePool::ReleaseWorker() {
  if (!t_in_task || t_released) return;
  t_released = true;
  std::lock_guard<std::mutex> lock(mu_);
  --busy_;
}

void ComputePool::WorkerLoop() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mu_);
      work_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping and drained
      task = std::move(queue_.front());
      queue_.pop_front();
      ++busy_;
    }
    t_in_task = true;
    t_released = false;
    task();
    t_in_task = false;
    if (t_released) continue;
    std::lock_guard<std::mutex> lock(mu_);
    --busy_;
  }
}

void ComputePool::Publish() { std::lock_guard<std::mutex> lock(mu_); }

size_t ComputePool::queued() const {
  std::lock_guard<std::mutex> lock(mu_);
  return queue_.size();
}

size_t ComputePool::busy() const {
  std::lock_guard<std::mutex> lock(mu_);
  return busy_;
}

uint64_t ComputePool::rejected() const {
  std::lock_guard<std::mutex> lock(mu_);
  return rejected_;
}

}  // namespace geodex::server
