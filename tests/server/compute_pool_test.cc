#include "compute_pool.h"
#include "server_test_util.h"

#include <atomic>

#include "gtest/gtest.h"

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

}  // namespace
}  // namespace geodex::server
