#include "measurements.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "absl/strings/str_format.h"
#include "harness/stats.h"

namespace geodex::bench {

Outcome RunGeodex(const MeshInfo& mesh, const std::vector<uint32_t>& sources,
                  const GeodesicOptions& options, int repeat, bool want_distances,
                  const Config& config) {
  Job job;
  job.task = Task::kGeodex;
  job.path = mesh.path;
  job.sources = sources;
  job.options = options;
  job.repeat = repeat;
  job.want_distances = want_distances;
  return RunChild(job, config.timeout_s, config.wait_idle_s);
}

Outcome RunPointJob(const MeshInfo& mesh, Job job, const Config& config) {
  job.path = mesh.path;
  return RunChild(job, config.timeout_s, config.wait_idle_s);
}

void Progress(const std::string& what, const Outcome& o) {
  std::fprintf(stderr, "  %-40s %-16s %9.2f s  peak RSS %6.0f MiB  other load %.2f\n", what.c_str(),
               o.ok() ? "ok" : o.StatusText().c_str(), o.elapsed_s, o.maxrss_kb / 1024.0,
               o.other_load);
}

std::string OtherLoad(const Outcome& o) {
  return o.elapsed_s >= 0.05 ? absl::StrFormat("%.2f", o.other_load) : "-";
}

uint64_t FilteredWindows(const SolveStats& s) {
  return s.windows_filtered_at_creation + s.windows_filtered_at_pop + s.windows_filtered_overfilter;
}

FieldDiff Compare(const std::vector<double>& a, const std::vector<double>& reference) {
  FieldDiff d;
  if (a.size() != reference.size()) {
    d.max_abs = d.max_rel = kInf;
    return d;
  }
  double largest = 0;
  for (double b : reference) {
    if (std::isfinite(b)) largest = std::max(largest, b);
  }
  double rel_sum = 0;
  uint64_t rel_count = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const bool fa = std::isfinite(a[i]), fb = std::isfinite(reference[i]);
    if (fa != fb) {
      ++d.finiteness_mismatch;
      continue;
    }
    if (!fa) continue;
    const double diff = std::abs(a[i] - reference[i]);
    if (a[i] != reference[i]) ++d.changed;
    d.max_abs = std::max(d.max_abs, diff);
    if (a[i] < reference[i] - 1e-12 * largest) ++d.below_reference;
    if (reference[i] > 0) {
      const double rel = diff / reference[i];
      d.max_pointwise_rel = std::max(d.max_pointwise_rel, rel);
      rel_sum += rel;
      ++rel_count;
    }
  }
  d.max_rel = largest > 0 ? d.max_abs / largest : 0;
  d.mean_pointwise_rel = rel_count > 0 ? rel_sum / rel_count : 0;
  return d;
}

}  // namespace geodex::bench
