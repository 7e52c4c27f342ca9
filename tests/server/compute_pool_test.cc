#include "compute_pool.h"

#include <atomic>

#include "absl/time/clock.h"
#include "gtest/gtest.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

TEST(ComputePoolTest, RunsEveryTask) {
  std::atomic<int> count{0};
  {
    ComputePool pool(2, 1000);
    for (int i = 0; i < 500; ++i) ASSERT_TRUE(pool.TrySubmit([&] { count.fetch_add(1); }));
  }  // the destructor drains the queue
  EXPECT_EQ(count.load(), 500);
}

TEST(ComputePoolTest, RejectsWhenWorkersBusyAndQueueFull) {
  testing::Notification started, release;  // outlive the pool, which joins its worker first
  ComputePool pool(1, 1);
  ASSERT_TRUE(pool.TrySubmit([&] {
    started.Notify();
    release.WaitForNotification();
  }));
  started.WaitForNotification();
  EXPECT_TRUE(pool.TrySubmit([] {}));   // waits in the queue
  EXPECT_FALSE(pool.TrySubmit([] {}));  // queue full
  EXPECT_EQ(pool.rejected(), 1u);
  release.Notify();
}

// A task that has handed its result over (ReleaseWorker) no longer counts against the capacity,
// though its thread has not returned yet: a client's next call must not be refused for it.
TEST(ComputePoolTest, ReleasedWorkerFreesItsPlaceBeforeTheTaskReturns) {
  testing::Notification released, finish;
  ComputePool pool(1, 0);
  ASSERT_TRUE(pool.TrySubmit([&] {
    pool.ReleaseWorker();
    pool.ReleaseWorker();  // a second call is a no-op (busy must not go below zero)
    released.Notify();
    finish.WaitForNotification();
  }));
  released.WaitForNotification();
  EXPECT_EQ(pool.busy(), 0u);
  std::atomic<bool> ran{false};
  EXPECT_TRUE(pool.TrySubmit([&] { ran = true; }));  // capacity 1 + 0, yet accepted
  EXPECT_FALSE(pool.TrySubmit([] {}));               // now it is full
  finish.Notify();
  pool.ReleaseWorker();  // outside a task: no effect
  for (int i = 0; i < 6000 && !ran.load(); ++i) absl::SleepFor(absl::Milliseconds(10));
  EXPECT_TRUE(ran.load());
  for (int i = 0; i < 6000 && pool.busy() != 0; ++i) absl::SleepFor(absl::Milliseconds(10));
  EXPECT_EQ(pool.busy(), 0u);
}

}  // namespace
}  // namespace geodex::server
