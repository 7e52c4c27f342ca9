// Single source / single target queries (A*, paper section 5), distance matrices and exact
// distances at surface points, against full-field solves of the same problem.

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "gtest/gtest.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

// A random vertex, edge point or face point of the mesh (file terms).
SurfacePoint RandomPoint(const MeshData& data, std::mt19937_64& rng) {
  const uint32_t nf = static_cast<uint32_t>(data.face_count());
  const uint32_t f = static_cast<uint32_t>(rng() % nf);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  switch (rng() % 3) {
    case 0:
      return SurfacePoint::AtVertex(data.faces[3 * f + rng() % 3]);
    case 1:
      return SurfacePoint::OnEdge(data.faces[3 * f], data.faces[3 * f + 1], u(rng));
    default: {
      const double a = u(rng), b = u(rng) * (1 - a);
      return SurfacePoint::InFace(f, a, b, 1 - a - b);
    }
  }
}

// d(p, q) the slow way: the exact value at q from the full field of p, by symmetry taking the
// point-to-vertex cases straight from the field and otherwise a full-field path query.
double FullFieldDistance(const TriangleMesh& mesh, const SurfacePoint& p, const SurfacePoint& q) {
  PathQueryOptions o;
  o.full_field = true;
  absl::StatusOr<PathQueryResult> r = ComputeShortestPath(mesh, p, q, o);
  EXPECT_TRUE(r.ok()) << r.status();
  return r.ok() ? r->distance : -1;
}

class PointQueryTest : public ::testing::TestWithParam<std::string> {};

TEST_P(PointQueryTest, AStarEqualsFullFieldAndPathLengthEqualsDistance) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok());
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok());
  std::mt19937_64 rng(11);
  uint64_t astar_windows = 0, full_windows = 0;
  for (int i = 0; i < 24; ++i) {
    const SurfacePoint p = RandomPoint(*data, rng), q = RandomPoint(*data, rng);
    SCOPED_TRACE(SurfacePointToString(p) + " -> " + SurfacePointToString(q));
    absl::StatusOr<PathQueryResult> astar = ComputeShortestPath(*mesh, p, q);
    ASSERT_TRUE(astar.ok()) << astar.status();
    PathQueryOptions full;
    full.full_field = true;
    absl::StatusOr<PathQueryResult> reference = ComputeShortestPath(*mesh, p, q, full);
    ASSERT_TRUE(reference.ok()) << reference.status();
    EXPECT_NEAR(astar->distance, reference->distance, 1e-12 * std::max(1.0, reference->distance));
    // The symmetric query gives the same distance.
    absl::StatusOr<PathQueryResult> back = ComputeShortestPath(*mesh, q, p);
    ASSERT_TRUE(back.ok());
    EXPECT_NEAR(back->distance, astar->distance, 1e-10 * std::max(1.0, astar->distance));
    // The polyline runs from p to q and has the reported length.
    EXPECT_NEAR(astar->path.length, astar->distance, 1e-12 * std::max(1.0, astar->distance));
    ASSERT_FALSE(astar->path.points.empty());
    EXPECT_EQ(SurfacePointToString(astar->path.points.back().where), SurfacePointToString(q));
    astar_windows += astar->stats.windows_created;
    full_windows += reference->stats.windows_created;
  }
  // The heuristic and the early stop save work overall.
  EXPECT_LT(astar_windows, full_windows);
}

TEST_P(PointQueryTest, MatrixEqualsPairwiseAnswers) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok());
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok());
  std::mt19937_64 rng(5);
  std::vector<SurfacePoint> sources, targets;
  for (int i = 0; i < 3; ++i) sources.push_back(RandomPoint(*data, rng));
  sources.push_back(sources.front());  // a repeated source is answered once, identically
  for (int i = 0; i < 5; ++i) targets.push_back(RandomPoint(*data, rng));
  absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(*mesh, sources, targets);
  ASSERT_TRUE(m.ok()) << m.status();
  ASSERT_EQ(m->rows, 4u);
  ASSERT_EQ(m->cols, 5u);
  for (size_t i = 0; i < m->rows; ++i) {
    for (size_t j = 0; j < m->cols; ++j) {
      const double d = FullFieldDistance(*mesh, sources[i], targets[j]);
      EXPECT_NEAR(m->values[i * m->cols + j], d, 1e-12 * std::max(1.0, d)) << i << "," << j;
    }
  }
  for (size_t j = 0; j < m->cols; ++j) EXPECT_EQ(m->values[3 * m->cols + j], m->values[j]);
}

TEST_P(PointQueryTest, ExactDistancesAtPointsMatchTheNearestSource) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok());
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok());
  std::mt19937_64 rng(9);
  const std::vector<SurfacePoint> sources = {RandomPoint(*data, rng), RandomPoint(*data, rng)};
  std::vector<SurfacePoint> points;
  for (int i = 0; i < 6; ++i) points.push_back(RandomPoint(*data, rng));
  absl::StatusOr<std::vector<std::pair<double, uint32_t>>> at =
      ComputeExactDistancesAt(*mesh, sources, points);
  ASSERT_TRUE(at.ok()) << at.status();
  for (size_t j = 0; j < points.size(); ++j) {
    const double d0 = FullFieldDistance(*mesh, sources[0], points[j]);
    const double d1 = FullFieldDistance(*mesh, sources[1], points[j]);
    const double best = std::min(d0, d1);
    EXPECT_NEAR((*at)[j].first, best, 1e-12 * std::max(1.0, best));
    if (std::abs(d0 - d1) > 1e-9 * best) {
      EXPECT_EQ((*at)[j].second, d0 < d1 ? 0u : 1u);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Meshes, PointQueryTest,
                         ::testing::Values("knight.off", "three-peaks.off", "kitten.off",
                                           "bump-domain.off"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n) {
                             if (c == '.' || c == '-') c = '_';
                           }
                           return n;
                         });

TEST(PointQueryTest, VertexToVertexMatchesTheField) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("fertility.off");
  ASSERT_TRUE(mesh.ok());
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(17)});
  ASSERT_TRUE(field.ok());
  for (uint32_t t : {0u, 100u, 2247u, 4000u, 4493u}) {
    absl::StatusOr<PathQueryResult> r =
        ComputeShortestPath(*mesh, SurfacePoint::AtVertex(17), SurfacePoint::AtVertex(t));
    ASSERT_TRUE(r.ok());
    EXPECT_NEAR(r->distance, field->distance[t], 1e-12 * std::max(1.0, field->distance[t])) << t;
  }
}

TEST(PointQueryTest, UnreachableTargetsAndBadPointsAreErrors) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(ComputeShortestPath(*mesh, SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(9999))
                .status()
                .code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ComputeDistanceMatrix(*mesh, {}, {SurfacePoint::AtVertex(1)}).status().code(),
            absl::StatusCode::kInvalidArgument);
  PathQueryOptions o;
  o.solver.max_distance = 1e-6;  // nothing but the source itself is within reach
  EXPECT_EQ(ComputeShortestPath(*mesh, SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(300), o)
                .status()
                .code(),
            absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace geodex
