#include "harness/peer_runner.h"

#include <fcntl.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iterator>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/string_view.h"
#include "harness/child_runner.h"
#include "harness/machine.h"
#include "harness/stats.h"

namespace geodex::bench {

PeerRun RunPeer(const std::string& command, const std::string& mesh_path, uint32_t source,
                int repeat, double timeout_s, double wait_idle_s) {
  PeerRun outcome;
  char out_path[] = "/tmp/geodex_bench_peer_XXXXXX";
  const int out_fd = mkstemp(out_path);
  if (out_fd < 0) {
    outcome.message = absl::StrCat("mkstemp: ", std::strerror(errno));
    return outcome;
  }
  close(out_fd);
  std::vector<double> times;
  for (int r = 0; r < repeat; ++r) {
    WaitForIdle(wait_idle_s);
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) break;
    const std::string line =
        absl::StrCat("exec ", command, " '", mesh_path, "' ", source, " '", out_path, "'");
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
      dup2(fds[1], STDOUT_FILENO);
      execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    std::string text;
    const bool timed_out = pid > 0 && ReadUntilEof(fds[0], pid, start, timeout_s, &text);
    close(fds[0]);
    int status = 0;
    struct rusage usage;
    std::memset(&usage, 0, sizeof usage);
    while (pid > 0 && wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
    }
    outcome.elapsed_s = MsSince(start) / 1000;
    outcome.maxrss_kb = std::max<int64_t>(outcome.maxrss_kb, usage.ru_maxrss);
    // The last line that starts with "ms=".
    size_t at = std::string::npos;
    for (size_t pos = text.find("ms="); pos != std::string::npos; pos = text.find("ms=", pos + 1)) {
      if (pos == 0 || text[pos - 1] == '\n') at = pos;
    }
    double ms = 0;
    if (timed_out) {
      outcome.kind = PeerRun::kTimeout;
      outcome.message = absl::StrFormat("timeout (killed after %g s)", timeout_s);
      break;
    }
    if (pid < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || at == std::string::npos ||
        !absl::SimpleAtod(absl::string_view(text).substr(at + 3).substr(
                              0, text.find_first_of(" \n", at) - at - 3),
                          &ms)) {
      outcome.kind = PeerRun::kFailed;
      outcome.message = absl::StrCat("peer failed (status ", status, "): ", text.substr(0, 200));
      break;
    }
    times.push_back(ms);
  }
  if (!times.empty() && static_cast<int>(times.size()) == repeat) {
    outcome.kind = PeerRun::kOk;
    outcome.runs = repeat;
    outcome.median_ms = Median(times);
    std::ifstream in(out_path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    outcome.distance.resize(bytes.size() / sizeof(double));
    std::memcpy(outcome.distance.data(), bytes.data(), outcome.distance.size() * sizeof(double));
    for (double& d : outcome.distance) {
      if (!(d < 1e300)) d = kInf;  // peers mark unreachable vertices in their own ways
    }
  }
  unlink(out_path);
  return outcome;
}

}  // namespace geodex::bench
