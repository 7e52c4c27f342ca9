// The geodexd binary as an operator runs it (a child process on 127.0.0.1, ports it picks):
// SIGTERM with a call in flight drains and exits 0, and a restart on the same data directory keeps
// every mesh and its answers. Every wait is bounded; only the children started here are signalled.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <regex>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using testing::FieldRequest;
using testing::GridOff;
using testing::ReadField;
using testing::Upload;

namespace fs = std::filesystem;

class Geodexd {
 public:
  Geodexd(const fs::path& dir, std::vector<std::string> extra)
      : log_(dir / absl::StrCat("geodexd-", next_log_++, ".log")) {
    std::vector<std::string> args = {GEODEXD_BINARY, "--listen", "127.0.0.1:0", "--data-dir",
                                     (dir / "data").string(), "--metrics_listen", "127.0.0.1:0",
                                     "--pool_threads", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    pid_ = ::fork();
    if (pid_ == 0) {
      std::FILE* out = std::freopen(log_.c_str(), "w", stdout);
      ::dup2(::fileno(out), 2);
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    // Wait (bounded) for both ports in the log.
    const std::regex grpc_port("listening on port ([0-9]+)"), metrics_port("127.0.0.1:([0-9]+)/metrics");
    for (int i = 0; i < 600 && (port_ == 0 || metrics_port_ == 0); ++i) {
      std::ifstream in(log_);
      std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      std::smatch m;
      if (std::regex_search(text, m, grpc_port)) port_ = std::stoi(m[1]);
      if (std::regex_search(text, m, metrics_port)) metrics_port_ = std::stoi(m[1]);
      if (port_ == 0) absl::SleepFor(absl::Milliseconds(50));
    }
    channel_ = grpc::CreateChannel(absl::StrCat("127.0.0.1:", port_),
                                   grpc::InsecureChannelCredentials());
    stub_ = v1::Geodex::NewStub(channel_);
  }
  ~Geodexd() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  // SIGTERM, then the exit status (-1 if it did not exit within `seconds`; then SIGKILL).
  int Terminate(double seconds) {
    ::kill(pid_, SIGTERM);
    for (int i = 0; i < seconds * 20; ++i) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      absl::SleepFor(absl::Milliseconds(50));
    }
    return -1;
  }
  std::string Log() const {
    std::ifstream in(log_);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }

  int port() const { return port_; }
  v1::Geodex::Stub& stub() { return *stub_; }

 private:
  static inline int next_log_ = 0;  // a fresh log per process: never read a previous one's port
  fs::path log_;
  pid_t pid_ = -1;
  bool exited_ = false;
  int port_ = 0;
  int metrics_port_ = 0;
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
