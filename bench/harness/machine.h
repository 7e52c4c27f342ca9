#pragma once

// The machine a benchmark runs on: what it is (CPU, cores, the build's commit), how busy the other
// processes keep it, and the clocks the measurements read.

#include <chrono>
#include <string>

namespace geodex::bench {

// What `command` (run by sh) prints on stdout; empty if it could not be run.
std::string RunCommand(const std::string& command);

// /proc/cpuinfo's first "model name", or "unknown".
std::string CpuModel();
// The cores this process may run on (its affinity mask).
int UsableCpus();
// "0.25 (1 min), 0.61 (5 min)" from /proc/loadavg.
std::string LoadAverage();
// "2026-11-26 12:44 UTC".
std::string UtcNow();
// "built from BUILT_FROM", plus " (the checkout is now at HEAD: rebuild?)" when `git` finds the
// checkout at `source_dir` at another commit.
std::string GitDescription(const std::string& built_from, const std::string& source_dir);

// Milliseconds of wall time since `since` (steady clock).
double MsSince(std::chrono::steady_clock::time_point since);
// CPU time of this process (user + system), in ms.
double CpuMs();

// CPU seconds spent busy by the whole machine since boot (all cores), from /proc/stat.
double MachineBusySeconds();
// Load from other processes, in cores, over `seconds` (this process sleeps meanwhile).
double SampleOtherLoad(double seconds);
// Waits until other processes use less than a quarter of a core (sampled over 0.5 s), at most
// `max_s` seconds. Returns the last sample.
double WaitForIdle(double max_s);

}  // namespace geodex::bench
