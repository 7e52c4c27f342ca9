#pragma once

// The child runner: every measurement runs in its own fork()ed child, one at a time. The child
// writes its result as bytes to a pipe; the parent reads it until EOF, kills a child that runs past
// its timeout, and takes from wait4 the child's wall time, its peak RSS (ru_maxrss: the kernel's
// high-water mark, which the child may reset once its input is loaded, see peak_memory.h) and the
// load other processes put on the machine meanwhile (from /proc/stat).

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace geodex::bench {

struct ChildOptions {
  double timeout_s = 300;  // the child is killed (SIGKILL) after this long
  // A measurement first waits for an idle machine (WaitForIdle, up to wait_idle_s) and counts in
  // MeasurementLoadSoFar(); anything else (loading a mesh to describe it) does neither.
  bool measurement = true;
  double wait_idle_s = 0;
};

// What the parent saw of one child.
struct ChildRun {
  bool started = false;  // false: no child ran (pipe or fork failed, `error` says which)
  std::string error;
  bool timed_out = false;  // killed after ChildOptions::timeout_s
  std::string bytes;       // everything the child wrote to its end of the pipe
  int status = 0;          // wait4's status
  int64_t maxrss_kb = 0;   // the child's ru_maxrss
  double elapsed_s = 0;
  double other_load = 0;  // cores used by other processes while the child ran
};

// Runs `child(fd)` in a fork()ed child that then exits; `fd` is the write end of the pipe whose
// contents come back in ChildRun::bytes. stdout and stderr are flushed before the fork.
ChildRun RunInChild(const std::function<void(int fd)>& child, const ChildOptions& options);

// Measurements of 50 ms or more so far (shorter ones are below /proc/stat's 10 ms ticks), those
// that ran while other processes used a quarter of a core or more, and the most they used.
struct MeasurementLoad {
  int busy = 0;
  int all = 0;
  double max_other_load = 0;
};
const MeasurementLoad& MeasurementLoadSoFar();

// Reads `fd` into *out until EOF; kills `pid` and returns true once `timeout_s` since `start` has
// passed. (Also the peer runner's.)
bool ReadUntilEof(int fd, pid_t pid, std::chrono::steady_clock::time_point start, double timeout_s,
                  std::string* out);

// write(2) until all of `data` is written or an error other than EINTR.
void WriteAll(int fd, const char* data, size_t size);

}  // namespace geodex::bench
