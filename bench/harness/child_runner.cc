#include "harness/child_runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"
#include "harness/machine.h"

namespace geodex::bench {
namespace {

MeasurementLoad measurement_load;

}  // namespace

const MeasurementLoad& MeasurementLoadSoFar() { return measurement_load; }

bool ReadUntilEof(int fd, pid_t pid, std::chrono::steady_clock::time_point start, double timeout_s,
                  std::string* out) {
  std::vector<char> buf(1 << 16);
  while (true) {
    const double left_ms = timeout_s * 1000 - MsSince(start);
    if (left_ms <= 0) {
      kill(pid, SIGKILL);
      return true;
    }
    struct pollfd p = {fd, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min(left_ms + 1, 60'000.0)));
    if (ready < 0 && errno != EINTR) return false;
    if (ready <= 0) continue;
    const ssize_t n = read(fd, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;  // EOF: the child has sent everything
    out->append(buf.data(), static_cast<size_t>(n));
  }
}

void WriteAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return;
    }
    data += n;
    size -= static_cast<size_t>(n);
  }
}

ChildRun RunInChild(const std::function<void(int fd)>& child, const ChildOptions& options) {
  ChildRun run;
  if (options.measurement) WaitForIdle(options.wait_idle_s);
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    run.error = absl::StrCat("pipe: ", std::strerror(errno));
    return run;
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const auto start = std::chrono::steady_clock::now();
  const double busy_start = MachineBusySeconds();
  const pid_t pid = fork();
  if (pid < 0) {
    run.error = absl::StrCat("fork: ", std::strerror(errno));
    close(fds[0]);
    close(fds[1]);
    return run;
  }
  if (pid == 0) {
    close(fds[0]);
    child(fds[1]);
    close(fds[1]);
    _exit(0);
  }
  run.started = true;
  close(fds[1]);
  run.timed_out = ReadUntilEof(fds[0], pid, start, options.timeout_s, &run.bytes);
  close(fds[0]);
  struct rusage usage;
  std::memset(&usage, 0, sizeof(usage));
  while (wait4(pid, &run.status, 0, &usage) < 0 && errno == EINTR) {
  }
  run.elapsed_s = MsSince(start) / 1000;
  run.maxrss_kb = usage.ru_maxrss;
  const double child_cpu_s = usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 +
                             usage.ru_stime.tv_sec + usage.ru_stime.tv_usec * 1e-6;
  run.other_load = std::max(
      0.0, (MachineBusySeconds() - busy_start - child_cpu_s) / std::max(run.elapsed_s, 1e-3));
  if (options.measurement && run.elapsed_s >= 0.05) {
    // (Shorter runs are below /proc/stat's 10 ms resolution.)
    ++measurement_load.all;
    if (run.other_load >= 0.25) ++measurement_load.busy;
    measurement_load.max_other_load = std::max(measurement_load.max_other_load, run.other_load);
  }
  return run;
}

}  // namespace geodex::bench
