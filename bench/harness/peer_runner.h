#pragma once

// The peer runner: another project's exact code (VTP, say: built by you, outside the repository)
// timed next to ours. Its command is run as `COMMAND MESH SOURCE OUT`, exec'd by sh in a process of
// its own (so wait4's peak RSS is the peer's): it must write the distance of every file vertex as
// raw doubles to OUT and print a line starting ms=<propagation ms>.

#include <cstdint>
#include <string>
#include <vector>

namespace geodex::bench {

struct PeerRun {
  enum Kind {
    kError,    // no run (a temporary file or a pipe could not be made)
    kOk,       // every repeat printed its ms= line
    kTimeout,  // killed after the timeout
    kFailed,   // a non-zero exit, or no ms= line: `message` has the status and its output
  } kind = kError;
  std::string message;
  int runs = 0;
  double median_ms = 0;          // the median of the ms= values
  std::vector<double> distance;  // from OUT, +inf where the peer wrote 1e300 or more (or NaN)
  int64_t maxrss_kb = 0;         // the largest ru_maxrss over the repeats
  double elapsed_s = 0;          // the last run's wall time, in seconds
};

// Runs `command` `repeat` times on `mesh_path` from file vertex `source`; before each run waits up
// to `wait_idle_s` for an idle machine; a run past `timeout_s` is killed and ends the series.
PeerRun RunPeer(const std::string& command, const std::string& mesh_path, uint32_t source,
                int repeat, double timeout_s, double wait_idle_s);

}  // namespace geodex::bench
