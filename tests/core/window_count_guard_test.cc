// A guard on the engine's work: on a fixed set of (mesh, sources, options) cases, the windows a
// solve creates may not grow more than 2% over the counts recorded in
// tests/data/window_counts.tsv (with the commit that set them; scripts/window_counts.sh rewrites
// it). A pruning rule that silently stops pruning still gives exact answers, so only this catches
// it. Counts are deterministic: the engine uses no fast-math, threads or clocks.

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_split.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "gtest/gtest.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

struct Recorded {
  std::string mesh, method, sources;
  double lambda = 0;
  uint64_t created = 0, processed = 0;
};

std::vector<Recorded> ReadRecorded() {
  std::ifstream in(TestDataPath("window_counts.tsv"));
  std::vector<Recorded> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f = absl::StrSplit(line, '\t');
    if (f.size() != 6) {
      ADD_FAILURE() << "window_counts.tsv: bad line '" << line << "'";
      continue;
    }
    Recorded r;
    r.mesh = f[0];
    r.method = f[1];
    r.lambda = std::stod(f[2]);
    r.sources = f[3];
    r.created = std::stoull(f[4]);
    r.processed = std::stoull(f[5]);
    out.push_back(r);
  }
  return out;
}

TEST(WindowCountGuardTest, NoCaseCreatesMoreThanTwoPercentMoreWindows) {
  const std::vector<Recorded> cases = ReadRecorded();
  ASSERT_GE(cases.size(), 10u) << "tests/data/window_counts.tsv is missing or short";
  for (const Recorded& r : cases) {
    SCOPED_TRACE(r.mesh + " " + r.method + " lambda " + std::to_string(r.lambda) + " sources " +
                 r.sources);
    absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(r.mesh);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    absl::StatusOr<std::vector<SurfacePoint>> sources = ParseSurfacePoints(r.sources);
    ASSERT_TRUE(sources.ok()) << sources.status();
    GeodesicOptions options;
    ASSERT_TRUE(r.method == "exact" || r.method == "ich") << r.method;
    options.method = r.method == "ich" ? Method::kIch : Method::kExact;
    options.lambda = r.lambda;
    absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, *sources, options);
    ASSERT_TRUE(field.ok()) << field.status();
    const uint64_t created = field->stats.windows_created;
    EXPECT_LE(created, r.created * 1.02)
        << "windows created grew from " << r.created << " to " << created
        << ": a pruning rule got weaker (if on purpose, rerun scripts/window_counts.sh)";
    if (created < r.created * 0.98) {
      std::printf("note: %s %s: %llu windows, %llu recorded: rerun scripts/window_counts.sh\n",
                  r.mesh.c_str(), r.sources.c_str(), static_cast<unsigned long long>(created),
                  static_cast<unsigned long long>(r.created));
    }
  }
}

}  // namespace
}  // namespace geodex
