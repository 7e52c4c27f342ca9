#pragma once

#include <atomic>

namespace geodex {

// Set from any thread to stop a solve; the engine polls it every few thousand windows and returns
// absl::CancelledError. A server wires deadlines and client cancellation to it.
class CancelToken {
 public:
  void Cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool IsCancelled() const { return cancelled_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> cancelled_{false};
};

}  // namespace geodex
