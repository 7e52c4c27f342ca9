// The geodexd binary as an operator runs it (a child process on 127.0.0.1, ports it picks):
// SIGTERM with a call in flight drains and exits 0, and a restart on the same data directory keeps
// every mesh and its answers. Every wait is bounded; only the children started here are signalled.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "server_test_util.h"
#include "testkit/geodexd_child.h"

namespace geodex::server {
namespace {

using testing::FieldRequest;
using testing::GridOff;
using testing::ReadField;
using testing::Upload;

namespace fs = std::filesystem;

// The binary (testkit/geodexd_child.h) on DIR/data, one worker, with a client stub.
class Geodexd {
 public:
  Geodexd(const fs::path& dir, std::vector<std::string> extra)
      : child_(Args(dir, std::move(extra)), dir / absl::StrCat("geodexd-", next_log_++, ".log")) {
    channel_ = grpc::CreateChannel(absl::StrCat("127.0.0.1:", child_.port()),
                                   grpc::InsecureChannelCredentials());
    stub_ = v1::Geodex::NewStub(channel_);
  }
  int Terminate(double seconds) { return child_.Terminate(seconds); }
  std::string Log() const { return child_.Log(); }
  int port() const { return child_.port(); }
  v1::Geodex::Stub& stub() { return *stub_; }

 private:
  static std::vector<std::string> Args(const fs::path& dir, std::vector<std::string> extra) {
    std::vector<std::string> args = {
        GEODEXD_BINARY,     "--listen",    "127.0.0.1:0",    "--data-dir", (dir / "data").string(),
        "--metrics_listen", "127.0.0.1:0", "--pool_threads", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  static inline int next_log_ = 0;  // a fresh log per process: never read a previous one's port
  testing_support::GeodexdChild child_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Geodex::Stub> stub_;
};

class GeodexdProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           absl::StrCat("geodexd-process-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name(), "-",
                        ::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (std::getenv("GEODEX_KEEP_TEST_DIR") == nullptr) fs::remove_all(dir_);
  }
  fs::path dir_;
};

TEST_F(GeodexdProcessTest, RestartKeepsMeshesIdsAndAnswers) {
  std::string name;
  testing::FieldResult before;
  {
    Geodexd server(dir_, {});
    ASSERT_GT(server.port(), 0) << server.Log();
    testing::UploadResult up = Upload(server.stub(), GridOff(14, 10, true), "valley");
    ASSERT_TRUE(up.status.ok()) << up.status.error_message();
    name = up.mesh.name();
    before = ReadField(server.stub(), FieldRequest("meshes/valley", {3, 77}));
    ASSERT_TRUE(before.status.ok());
    EXPECT_EQ(server.Terminate(60), 0) << server.Log();
  }
  Geodexd again(dir_, {});
  ASSERT_GT(again.port(), 0) << again.Log();
  EXPECT_NE(again.Log().find("4 meshes indexed"), std::string::npos) << again.Log();  // + samples
  testing::FieldResult after = ReadField(again.stub(), FieldRequest(name, {3, 77}));
  ASSERT_TRUE(after.status.ok()) << after.status.error_message();
  EXPECT_EQ(after.distances, before.distances);
  EXPECT_EQ(after.labels, before.labels);
  testing::UploadResult reupload = Upload(again.stub(), GridOff(14, 10, true));
  EXPECT_EQ(reupload.mesh.name(), name);
  EXPECT_TRUE(ReadField(again.stub(), FieldRequest("meshes/terrain", {0})).status.ok());
  EXPECT_EQ(again.Terminate(60), 0);
}

TEST_F(GeodexdProcessTest, SigtermWithACallInFlightDrainsAndExitsZero) {
  // A call that is running when SIGTERM arrives finishes within the grace period...
  {
    Geodexd server(dir_, {"--shutdown_grace_seconds", "60", "--samples=false"});
    ASSERT_GT(server.port(), 0) << server.Log();
    ASSERT_TRUE(Upload(server.stub(), GridOff(120, 120, false), "flat").status.ok());
    auto call = std::async(std::launch::async, [&] {
      return ReadField(server.stub(), FieldRequest("meshes/flat", {7260}), 120);
    });
    // Give the call time to reach the worker (behaviour does not depend on it: it is either
    // running or done when the signal arrives, and must succeed either way).
    absl::SleepFor(absl::Milliseconds(300));
    EXPECT_EQ(server.Terminate(120), 0) << server.Log();
    testing::FieldResult result = call.get();
    EXPECT_TRUE(result.status.ok()) << result.status.error_message();
    EXPECT_EQ(result.distances.size(), 121u * 121u);
    EXPECT_NE(server.Log().find("shutting down"), std::string::npos);
  }
  // ...and one that outlives it is cancelled at the grace deadline; the exit is still clean.
  {
    Geodexd server(dir_, {"--shutdown_grace_seconds", "0.5", "--samples=false"});
    ASSERT_GT(server.port(), 0) << server.Log();
    ASSERT_TRUE(Upload(server.stub(), GridOff(400, 400, false), "big").status.ok());
    auto call = std::async(std::launch::async, [&] {
      return ReadField(server.stub(), FieldRequest("meshes/big", {80400}), 300);
    });
    absl::SleepFor(absl::Milliseconds(500));
    const absl::Time start = absl::Now();
    EXPECT_EQ(server.Terminate(120), 0) << server.Log();
    testing::FieldResult result = call.get();
    EXPECT_FALSE(result.status.ok());
    EXPECT_LT(absl::Now() - start, absl::Seconds(100));  // not the full solve
  }
}

}  // namespace
}  // namespace geodex::server
