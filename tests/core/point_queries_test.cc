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
#include "util/mesh_factory.h"
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

// --- Directions at surface points (PointQuery::directions) ---

Vec3 Unit(const Vec3& from, const Vec3& to) {
  const double n = Distance3(from, to);
  return {(to[0] - from[0]) / n, (to[1] - from[1]) / n, (to[2] - from[2]) / n};
}

// On a plane each point heads straight at its nearest source, from vertices, edge points and
// face points alike; a source itself has no direction.
TEST(PointDirectionTest, OnAPlaneEachPointHeadsStraightAtItsNearestSource) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 12;
  spec.jitter = 0.15;
  const MeshData data = MakeGrid(spec);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok());
  std::mt19937_64 rng(21);
  PointQuery query;
  query.sources = {SurfacePoint::AtVertex(30), SurfacePoint::InFace(200, 0.2, 0.5, 0.3)};
  for (int i = 0; i < 40; ++i) query.points.push_back(RandomPoint(data, rng));
  // Edge points on each of a face's three edges (the solver places them in either face).
  for (uint32_t f : {7u, 90u, 150u, 251u}) {
    for (int k = 0; k < 3; ++k) {
      query.points.push_back(
          SurfacePoint::OnEdge(data.faces[3 * f + k], data.faces[3 * f + (k + 1) % 3], 0.375));
    }
  }
  query.points.push_back(query.sources[1]);
  query.directions = true;
  absl::StatusOr<PointValues> v = ComputePointValues(*mesh, query);
  ASSERT_TRUE(v.ok()) << v.status();
  ASSERT_EQ(v->direction.size(), query.points.size());
  const Vec3 s0 = PositionOf(data, query.sources[0]), s1 = PositionOf(data, query.sources[1]);
  for (size_t j = 0; j + 1 < query.points.size(); ++j) {
    const Vec3 p = PositionOf(data, query.points[j]);
    const double d0 = Distance3(p, s0), d1 = Distance3(p, s1);
    if (std::abs(d0 - d1) < 1e-6 || std::min(d0, d1) < 1e-9) continue;  // a tie, or on a source
    const Vec3 want = Unit(p, d0 < d1 ? s0 : s1);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(v->direction[j][c], want[c], 1e-9) << SurfacePointToString(query.points[j]);
    }
    EXPECT_EQ(v->source[j], d0 < d1 ? 0u : 1u);
  }
  EXPECT_EQ(v->direction.back(), (std::array<double, 3>{0, 0, 0}));
  // The distances are those of the query without directions.
  query.directions = false;
  absl::StatusOr<PointValues> plain = ComputePointValues(*mesh, query);
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->direction.empty());
  EXPECT_EQ(plain->distance, v->distance);
}

// In an L, a point hidden from the source behind the reflex corner heads for the corner, not for
// the source; one in sight heads for the source.
TEST(PointDirectionTest, InAnLAPointBehindTheCornerHeadsForTheCorner) {
  const double size = 2;
  const MeshData data = MakeLShape(6, size, 0.1);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok());
  std::mt19937_64 rng(5);
  PointQuery query;
  // A face point high in the left arm (x < size/2, y > size/2).
  SurfacePoint source;
  for (;;) {
    source = RandomPoint(data, rng);
    const Vec3 p = PositionOf(data, source);
    if (p[0] < 0.3 * size && p[1] > 0.8 * size && source.kind == SurfacePoint::Kind::kFace) break;
  }
  query.sources = {source};
  for (int i = 0; i < 400 && query.points.size() < 30; ++i) {
    const SurfacePoint p = RandomPoint(data, rng);
    if (PositionOf(data, p)[1] < 0.45 * size) query.points.push_back(p);  // the lower arm
  }
  query.directions = true;
  absl::StatusOr<PointValues> v = ComputePointValues(*mesh, query);
  ASSERT_TRUE(v.ok()) << v.status();
  const Vec3 s = PositionOf(data, source);
  const Vec2 corner = LShapeReflexCorner(size);
  int hidden = 0, seen = 0;
  for (size_t j = 0; j < query.points.size(); ++j) {
    const Vec3 p = PositionOf(data, query.points[j]);
    const double d = LShapeDistance(size, {s[0], s[1]}, {p[0], p[1]});
    EXPECT_NEAR(v->distance[j], d, 1e-12 * d);
    const bool bends = d > Distance3(s, p) + 1e-9;
    const Vec3 want = bends ? Unit(p, {corner[0], corner[1], 0}) : Unit(p, s);
    (bends ? hidden : seen)++;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(v->direction[j][c], want[c], 1e-9) << SurfacePointToString(query.points[j]);
    }
  }
  EXPECT_GT(hidden, 5);  // both cases are exercised
  EXPECT_GT(seen, 0);
}

// A sheet folded along x = 1/2: from points on the fold (vertices, and edge points the solver may
// place in the far face) and in the flat half holding the source, the direction is the straight
// 3D line to the source; a point beyond the fold heads for the fold in its own plane.
TEST(PointDirectionTest, OnAFoldedSheetPointsOnTheFoldHeadStraightAtTheSource) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 12;
  MeshData data = MakeGrid(spec);
  const double slope = 0.8;
  for (size_t v = 0; v < data.vertex_count(); ++v) {
    const double x = data.positions[3 * v];
    if (x > 0.5) data.positions[3 * v + 2] = (x - 0.5) * slope;
  }
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok());
  PointQuery query;
  query.sources = {SurfacePoint::InFace(124, 0.3, 0.3, 0.4)};  // in the flat half
  const Vec3 s = PositionOf(data, query.sources[0]);
  ASSERT_LT(s[0], 0.5);
  std::vector<bool> on_fold;
  for (uint32_t j = 0; j < 12; ++j) {
    const uint32_t a = j * 13 + 6, b = (j + 1) * 13 + 6;  // vertices at x = 1/2
    query.points.push_back(SurfacePoint::AtVertex(a));
    query.points.push_back(SurfacePoint::OnEdge(a, b, 0.25 + 0.04 * j));
    query.points.push_back(SurfacePoint::OnEdge(b, a, 0.6));
  }
  on_fold.assign(query.points.size(), true);
  for (uint32_t f = 0; f < data.face_count(); f += 7) {  // face points on both sides
    query.points.push_back(SurfacePoint::InFace(f, 0.2, 0.5, 0.3));
    on_fold.push_back(false);
  }
  query.directions = true;
  absl::StatusOr<PointValues> v = ComputePointValues(*mesh, query);
  ASSERT_TRUE(v.ok()) << v.status();
  int beyond = 0;
  for (size_t j = 0; j < query.points.size(); ++j) {
    const Vec3 p = PositionOf(data, query.points[j]);
    Vec3 want;
    if (p[0] <= 0.5) {
      want = Unit(p, s);
    } else {
      // Unfold the far half onto the plane: the path is straight there and crosses x = 1/2.
      const double u = 0.5 + (p[0] - 0.5) * std::sqrt(1 + slope * slope);  // unfolded x
      const double t = (u - 0.5) / (u - s[0]);  // where p -> s meets the fold, as a fraction
      const Vec3 cross{0.5, p[1] + (s[1] - p[1]) * t, 0};
      want = Unit(p, cross);
      ++beyond;
    }
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(v->direction[j][c], want[c], 1e-9)
          << SurfacePointToString(query.points[j]) << (on_fold[j] ? " (on the fold)" : "");
    }
  }
  EXPECT_GT(beyond, 5);
}

// At vertices the directions are the direction field's (ComputeDirectionField reads them off the
// full field's origins; here they come from a targeted solve's trace); beyond max_distance NaN.
TEST(PointDirectionTest, AtVerticesTheyAreTheDirectionFieldAndNaNWhereUnreachable) {
  for (const char* name : {"knight.off", "kitten.off"}) {
    absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(name);
    ASSERT_TRUE(mesh.ok());
    const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(3)};
    absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sources);
    ASSERT_TRUE(field.ok());
    const std::vector<std::array<double, 3>> dir = ComputeDirectionField(*mesh, *field);
    PointQuery query;
    query.sources = sources;
    for (uint32_t v = 0; v < mesh->file_vertex_count(); v += 97) {
      query.points.push_back(SurfacePoint::AtVertex(v));
    }
    query.directions = true;
    absl::StatusOr<PointValues> at = ComputePointValues(*mesh, query);
    ASSERT_TRUE(at.ok()) << at.status();
    for (size_t j = 0; j < query.points.size(); ++j) {
      const uint32_t v = query.points[j].vertex;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(at->direction[j][c], dir[v][c], 1e-9) << name << " " << v;
      }
    }
    query.options.max_distance = 1e-9;  // only the source within reach
    query.points = {SurfacePoint::AtVertex(3), SurfacePoint::AtVertex(200)};
    at = ComputePointValues(*mesh, query);
    ASSERT_TRUE(at.ok()) << at.status();
    EXPECT_EQ(at->direction[0], (std::array<double, 3>{0, 0, 0}));
    EXPECT_TRUE(std::isnan(at->direction[1][0]) && std::isnan(at->direction[1][2]));
  }
}

}  // namespace
}  // namespace geodex
