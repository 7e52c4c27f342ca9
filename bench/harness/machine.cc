#include "harness/machine.h"

#include <sched.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"

namespace geodex::bench {

std::string RunCommand(const std::string& command) {
  std::string out;
  if (FILE* p = popen(command.c_str(), "r")) {
    char buf[256];
    while (fgets(buf, sizeof(buf), p) != nullptr) out += buf;
    pclose(p);
  }
  return out;
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (absl::StartsWith(line, "model name")) {
      if (const size_t colon = line.find(':'); colon != std::string::npos) {
        return std::string(absl::StripAsciiWhitespace(line.substr(colon + 1)));
      }
    }
  }
  return "unknown";
}

int UsableCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return CPU_COUNT(&set);
  return static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double one = 0, five = 0;
  in >> one >> five;
  return absl::StrFormat("%.2f (1 min), %.2f (5 min)", one, five);
}

std::string UtcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm;
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

std::string GitDescription(const std::string& built_from, const std::string& source_dir) {
  std::string description = absl::StrCat("built from ", built_from);
  const std::string head(absl::StripAsciiWhitespace(
      RunCommand("git -C '" + source_dir + "' rev-parse --short HEAD 2>/dev/null")));
  if (!head.empty() && !absl::StartsWith(built_from, head)) {
    absl::StrAppend(&description, " (the checkout is now at ", head, ": rebuild?)");
  }
  return description;
}

double MsSince(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

double CpuMs() {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

double MachineBusySeconds() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  uint64_t user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
  in >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal;
  return static_cast<double>(user + nice + system + irq + softirq + steal) /
         static_cast<double>(sysconf(_SC_CLK_TCK));
}

double SampleOtherLoad(double seconds) {
  const double busy = MachineBusySeconds();
  usleep(static_cast<useconds_t>(seconds * 1e6));
  return (MachineBusySeconds() - busy) / seconds;
}

double WaitForIdle(double max_s) {
  if (max_s <= 0) return 0;
  const auto start = std::chrono::steady_clock::now();
  double load = SampleOtherLoad(0.5);
  bool said = false;
  while (load >= 0.25 && MsSince(start) < max_s * 1000) {
    if (!said) std::fprintf(stderr, "  (waiting for an idle machine: other load %.2f)\n", load);
    said = true;
    load = SampleOtherLoad(0.5);
  }
  return load;
}

}  // namespace geodex::bench
