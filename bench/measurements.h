#pragma once

// One measurement as the sections run it (a geodex solve or a targeted-query task in its own child
// on a mesh) and what they read off its outcome: a progress line, the windows the filter removed,
// and the difference between two distance fields.

#include <cstdint>
#include <string>
#include <vector>

#include "child_tasks.h"
#include "config.h"
#include "geodex/geodesic_solver.h"
#include "meshes.h"

namespace geodex::bench {

// A kGeodex child: ComputeDistanceField on `mesh` from `sources` with `options`, `repeat` times.
Outcome RunGeodex(const MeshInfo& mesh, const std::vector<uint32_t>& sources,
                  const GeodesicOptions& options, int repeat, bool want_distances,
                  const Config& config);
// `job` in its own child on `mesh`.
Outcome RunPointJob(const MeshInfo& mesh, Job job, const Config& config);

// One line on stderr: what ran, its status, its time, its peak RSS and the other load.
void Progress(const std::string& what, const Outcome& o);
// The other load during the measurement, "-" below 50 ms (the /proc/stat sample, 10 ms ticks,
// says nothing).
std::string OtherLoad(const Outcome& o);

// Lemma 2 filter removals: at creation + at pop + lambda over-filter.
uint64_t FilteredWindows(const SolveStats& s);

// Differences between two per-vertex fields, over vertices where both are finite.
struct FieldDiff {
  double max_abs = 0;
  double max_rel = 0;            // max_abs / the largest finite reference distance
  double max_pointwise_rel = 0;  // max |a - b| / b over b > 0
  double mean_pointwise_rel = 0;
  uint64_t changed = 0;              // vertices with a != b
  uint64_t finiteness_mismatch = 0;  // finite in one, +inf in the other
  uint64_t below_reference = 0;      // a < b - 1e-12 * largest (for "a is an upper bound" checks)
};

FieldDiff Compare(const std::vector<double>& a, const std::vector<double>& reference);

}  // namespace geodex::bench
