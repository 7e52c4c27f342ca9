// Distance matrices for planners (issue 19): rows in parallel, symmetric matrices solved once per
// pair, k nearest, max_distance, lambda, progress and cancellation, checked against single
// ComputeShortestPath queries (exact either way).

#include "geodex/distance_matrix.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "geodex/cancel.h"
#include "geodex/shortest_path.h"
#include "gtest/gtest.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

double Distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// `n` waypoints: vertices within `radius_rel` of the bounding-box diagonal around a vertex (a
// robot's local plan), every other one moved onto a face of that vertex.
std::vector<SurfacePoint> LocalWaypoints(const TriangleMesh& mesh, size_t n, double radius_rel,
                                         uint32_t seed) {
  std::mt19937 rng(seed);
  double diagonal = Distance(mesh.BoundsMin(), mesh.BoundsMax());
  const uint32_t centre = rng() % mesh.file_vertex_count();
  std::vector<uint32_t> near;
  for (uint32_t v = 0; v < mesh.file_vertex_count(); ++v) {
    if (Distance(mesh.Position(v), mesh.Position(centre)) <= radius_rel * diagonal)
      near.push_back(v);
  }
  std::shuffle(near.begin(), near.end(), rng);
  std::vector<SurfacePoint> out;
  for (size_t i = 0; i < n && i < near.size(); ++i) out.push_back(SurfacePoint::AtVertex(near[i]));
  // Face points too: the first face containing each odd waypoint's vertex.
  for (size_t i = 1; i < out.size(); i += 2) {
    for (uint32_t f = 0; f < mesh.face_count(); ++f) {
      if (mesh.FaceVertex(f, 0) == out[i].vertex && !mesh.FaceFlipped(f)) {
        out[i] = SurfacePoint::InFace(f, 0.5, 0.3, 0.2);
        break;
      }
    }
  }
  return out;
}

std::vector<SurfacePoint> SpreadPoints(const TriangleMesh& mesh, size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<SurfacePoint> out;
  for (size_t i = 0; i < n; ++i)
    out.push_back(SurfacePoint::AtVertex(rng() % mesh.file_vertex_count()));
  return out;
}

double PathDistance(const TriangleMesh& mesh, const SurfacePoint& a, const SurfacePoint& b) {
  absl::StatusOr<PathQueryResult> r = ComputeShortestPath(mesh, a, b);
  if (!r.ok()) return kUnreachable;
  return r->distance;
}

class DistanceMatrixTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DistanceMatrixTest, SymmetricMatricesAreSymmetricAndEqualPathQueries) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok());
  for (const std::vector<SurfacePoint>& points :
       {LocalWaypoints(*mesh, 12, 0.08, 1), SpreadPoints(*mesh, 9, 2)}) {
    std::vector<SurfacePoint> with_repeat = points;
    with_repeat.push_back(points[1]);  // a repeated point: its row and column are the same
    absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(*mesh, with_repeat, with_repeat);
    ASSERT_TRUE(m.ok()) << m.status();
    const size_t n = with_repeat.size();
    ASSERT_EQ(m->rows, n);
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = 0; j < n; ++j) {
        const double d = m->values[i * n + j];
        EXPECT_EQ(d, m->values[j * n + i]) << i << "," << j;  // bit for bit
        if (SurfacePointToString(with_repeat[i]) == SurfacePointToString(with_repeat[j])) {
          EXPECT_EQ(d, 0) << i << "," << j;
          continue;
        }
        const double single = PathDistance(*mesh, with_repeat[i], with_repeat[j]);
        EXPECT_NEAR(d, single, 1e-12 * std::max(1.0, single)) << i << "," << j;
      }
    }
  }
}

TEST_P(DistanceMatrixTest, OrderSizeAndThreadsDoNotChangeEntries) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok());
  const std::vector<SurfacePoint> points = LocalWaypoints(*mesh, 10, 0.1, 3);
  const size_t n = points.size();
  MatrixOptions one;
  one.threads = 1;
  MatrixOptions four;
  four.threads = 4;
  const DistanceMatrix a = *ComputeDistanceMatrix(*mesh, points, points, one);
  const DistanceMatrix b = *ComputeDistanceMatrix(*mesh, points, points, four);
  EXPECT_EQ(a.values, b.values);  // deterministic whatever the thread count
  // Reversed order, and a request split in two halves (non-symmetric): the same distances.
  std::vector<SurfacePoint> reversed(points.rbegin(), points.rend());
  const DistanceMatrix r = *ComputeDistanceMatrix(*mesh, reversed, reversed, four);
  const std::vector<SurfacePoint> half(points.begin(), points.begin() + n / 2);
  const DistanceMatrix h = *ComputeDistanceMatrix(*mesh, half, points, four);
  double scale = 0;
  for (double d : a.values) scale = std::max(scale, d);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j) {
      EXPECT_NEAR(a.values[i * n + j], r.values[(n - 1 - i) * n + (n - 1 - j)], 1e-12 * scale);
      if (i < n / 2) {
        EXPECT_NEAR(a.values[i * n + j], h.values[i * n + j], 1e-12 * scale);
      }
    }
  }
}

// on_final_row (streaming rows as they finish): every output row exactly once, in order, with the
// values of the returned matrix bit for bit, whatever the threads; a symmetric row only once the
// sweep's earlier rows (which solve its other pairs) are done.
TEST_P(DistanceMatrixTest, FinalRowsArriveInOrderWithTheMatrixValues) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok());
  std::vector<SurfacePoint> points = LocalWaypoints(*mesh, 10, 0.1, 5);
  points.push_back(points[2]);  // a repeated point
  const std::vector<SurfacePoint> targets = SpreadPoints(*mesh, 7, 6);
  for (unsigned threads : {1u, 3u}) {
    for (bool symmetric : {true, false}) {
      const std::vector<SurfacePoint>& cols = symmetric ? points : targets;
      std::vector<std::vector<double>> rows;
      MatrixOptions options;
      options.threads = threads;
      options.on_final_row = [&](size_t row, const double* values) {
        EXPECT_EQ(row, rows.size()) << "out of order";
        rows.emplace_back(values, values + cols.size());
      };
      absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(*mesh, points, cols, options);
      ASSERT_TRUE(m.ok()) << m.status();
      ASSERT_EQ(rows.size(), points.size()) << threads << " threads, symmetric " << symmetric;
      for (size_t i = 0; i < rows.size(); ++i) {
        for (size_t j = 0; j < cols.size(); ++j) {
          const double want = m->values[i * cols.size() + j];
          EXPECT_EQ(std::memcmp(&rows[i][j], &want, sizeof want), 0) << i << "," << j;
        }
      }
    }
  }
}

TEST_P(DistanceMatrixTest, KNearestKeepsExactlyTheKNearest) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok());
  const std::vector<SurfacePoint> sources = SpreadPoints(*mesh, 4, 4);
  const std::vector<SurfacePoint> targets = SpreadPoints(*mesh, 11, 5);
  const DistanceMatrix full = *ComputeDistanceMatrix(*mesh, sources, targets);
  for (uint32_t k : {1u, 3u, 11u, 20u}) {
    MatrixOptions o;
    o.k_nearest = k;
    absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(*mesh, sources, targets, o);
    ASSERT_TRUE(m.ok()) << m.status();
    for (size_t i = 0; i < m->rows; ++i) {
      std::vector<double> row(full.values.begin() + i * full.cols,
                              full.values.begin() + (i + 1) * full.cols);
      std::vector<double> sorted = row;
      std::sort(sorted.begin(), sorted.end());
      const size_t kept = std::min<size_t>(k, row.size());
      size_t finite = 0;
      for (size_t j = 0; j < m->cols; ++j) {
        const double d = m->values[i * m->cols + j];
        if (std::isinf(d)) continue;
        ++finite;
        EXPECT_NEAR(d, row[j], 1e-12 * std::max(1.0, row[j])) << "k " << k << " row " << i;
        EXPECT_LE(row[j], sorted[kept - 1] * (1 + 1e-12)) << "k " << k << " row " << i;
      }
      EXPECT_EQ(finite, kept) << "k " << k << " row " << i;
    }
  }
}

TEST_P(DistanceMatrixTest, MaxDistanceAndLambdaApplyToEveryRow) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok());
  const std::vector<SurfacePoint> points = SpreadPoints(*mesh, 8, 6);
  const DistanceMatrix exact = *ComputeDistanceMatrix(*mesh, points, points);
  std::vector<double> sorted = exact.values;
  std::sort(sorted.begin(), sorted.end());
  MatrixOptions capped;
  capped.solver.max_distance = sorted[sorted.size() / 2];
  const DistanceMatrix c = *ComputeDistanceMatrix(*mesh, points, points, capped);
  size_t cut = 0;
  for (size_t i = 0; i < exact.values.size(); ++i) {
    if (exact.values[i] > capped.solver.max_distance) {
      EXPECT_TRUE(std::isinf(c.values[i])) << i;
      ++cut;
    } else {
      EXPECT_EQ(c.values[i], exact.values[i]) << i;
    }
  }
  EXPECT_GT(cut, 0u);
  MatrixOptions coarse;
  coarse.solver.lambda = 0.3;
  const DistanceMatrix l = *ComputeDistanceMatrix(*mesh, points, points, coarse);
  for (size_t i = 0; i < exact.values.size(); ++i) {
    EXPECT_GE(l.values[i], exact.values[i] * (1 - 1e-12)) << i;  // over-filtering never shortens
  }
}

TEST(DistanceMatrixRunTest, ProgressCancellationAndLateHelpers) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("bump-domain.off");
  ASSERT_TRUE(mesh.ok());
  const std::vector<SurfacePoint> points = SpreadPoints(*mesh, 6, 7);
  // Helpers that only run after the call returned: the calling thread solves every row alone,
  // and the late helpers find nothing left to do.
  std::vector<std::function<void()>> late;
  std::vector<std::pair<size_t, size_t>> progress;
  MatrixOptions o;
  o.threads = 3;
  o.spawn = [&late](std::function<void()> f) { late.push_back(std::move(f)); };
  o.on_row = [&progress](size_t done, size_t total) { progress.push_back({done, total}); };
  absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(*mesh, points, points, o);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(late.size(), 2u);
  for (auto& f : late) f();
  EXPECT_EQ(m->values, ComputeDistanceMatrix(*mesh, points, points)->values);
  ASSERT_EQ(progress.size(), points.size());
  for (size_t i = 0; i < progress.size(); ++i) {
    EXPECT_EQ(progress[i].first, i + 1);
    EXPECT_EQ(progress[i].second, points.size());
  }
  // A cancelled call stops every row.
  CancelToken cancel;
  cancel.Cancel();
  MatrixOptions c;
  c.solver.cancel = &cancel;
  c.solver.max_windows = 0;
  const std::vector<SurfacePoint> many = SpreadPoints(*mesh, 16, 8);
  absl::StatusOr<DistanceMatrix> cancelled = ComputeDistanceMatrix(*mesh, many, many, c);
  // (Each row between points spread over the mesh pops far more windows than the engine's poll
  // interval, so the token is always seen.)
  EXPECT_EQ(cancelled.status().code(), absl::StatusCode::kCancelled) << cancelled.status();
  // A window budget too small for any row fails the whole call with its error.
  MatrixOptions tiny;
  tiny.solver.max_windows = 10;
  EXPECT_EQ(ComputeDistanceMatrix(*mesh, many, many, tiny).status().code(),
            absl::StatusCode::kResourceExhausted);
}

INSTANTIATE_TEST_SUITE_P(CommittedMeshes, DistanceMatrixTest,
                         ::testing::Values("knight.off", "kitten.off", "bump-domain.off"),
                         MeshFileParamName());

}  // namespace
}  // namespace geodex
