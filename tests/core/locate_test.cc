// SurfaceLocator: the nearest surface point against a brute-force scan over all faces, the
// closest-point-on-triangle routine against dense sampling, snapping to vertices and edges, the
// file's corner order on flipped faces, georeferenced coordinates and input errors.

#include "geodex/locate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Vec3 Add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 Sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 Scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Norm(const Vec3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

// File position of file face f's point with file-order barycentrics b.
Vec3 FacePoint(const MeshData& data, uint32_t f, const Vec3& b) {
  Vec3 p{0, 0, 0};
  for (int k = 0; k < 3; ++k) p = Add(p, Scale(VertexPosition(data, data.faces[3 * f + k]), b[k]));
  return p;
}

// Where a SurfacePoint lies, evaluated with the FILE's vertices and corner order.
Vec3 PointPosition(const MeshData& data, const SurfacePoint& p) {
  switch (p.kind) {
    case SurfacePoint::Kind::kVertex:
      return VertexPosition(data, p.vertex);
    case SurfacePoint::Kind::kEdge:
      return Add(Scale(VertexPosition(data, p.edge_from), 1 - p.t),
                 Scale(VertexPosition(data, p.edge_to), p.t));
    case SurfacePoint::Kind::kFace:
      return FacePoint(data, p.face, p.bary);
    case SurfacePoint::Kind::kPosition:
      return p.position;  // not produced by Locate
  }
  return {kNaN, kNaN, kNaN};
}

// The reference: every non-degenerate face, in recentred coordinates, lowest id on exact ties.
struct BruteResult {
  double distance = kInf;
  uint32_t face = kNoIndex;
  Vec3 position{};  // file coordinates
};
BruteResult BruteForce(const TriangleMesh& mesh, const Vec3& xyz) {
  const Vec3 q = Sub(xyz, mesh.Center());
  double best2 = kInf;
  BruteResult r;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    if (mesh.FaceDegenerate(f)) continue;
    const TriangleClosestPoint c = ClosestPointOnTriangle(q, mesh.Position(mesh.FaceVertex(f, 0)),
                                                          mesh.Position(mesh.FaceVertex(f, 1)),
                                                          mesh.Position(mesh.FaceVertex(f, 2)));
    if (c.distance2 < best2) {
      best2 = c.distance2;
      r.face = f;
      r.position = Add(c.point, mesh.Center());
    }
  }
  r.distance = std::sqrt(best2);
  return r;
}

double BoxDiagonal(const TriangleMesh& mesh) {
  return Norm(Sub(mesh.BoundsMax(), mesh.BoundsMin()));
}

// ------------------------------------------------------------------------------------------
// The closest-point routine itself, against a dense sampling of the triangle.

TEST(ClosestPointOnTriangleTest, MatchesDenseSampling) {
  const std::vector<std::array<Vec3, 3>> triangles = {
      {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}},                       // right angle
      {{{0, 0, 0}, {2, 0, 0}, {1.7, 0.3, 0}}},                   // obtuse at the third corner
      {{{-0.3, 0.2, 0.5}, {0.9, -0.4, 0.1}, {0.2, 0.8, -0.6}}},  // general position in 3D
      {{{0, 0, 0}, {1, 0.01, 0.02}, {0.5, 0.02, 0.03}}},         // sliver
      {{{0, 0, 0}, {2.5, 0, 0}, {1, 0, 0}}},                     // zero area: collinear
      {{{0.5, 0.5, 0}, {0.5, 0.5, 0}, {1, -0.5, 0.2}}},          // zero area: coincident
  };
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> uniform(-1.5, 2.0);
  constexpr int kGrid = 250;        // barycentric grid for the interior
  constexpr int kEdgeGrid = 20000;  // finer along the edges, where most answers land
  for (const auto& t : triangles) {
    const double longest =
        std::max({Norm(Sub(t[1], t[0])), Norm(Sub(t[2], t[1])), Norm(Sub(t[0], t[2]))});
    std::vector<Vec3> samples;
    for (int i = 0; i <= kGrid; ++i) {
      for (int j = 0; i + j <= kGrid; ++j) {
        const double v = double(i) / kGrid, w = double(j) / kGrid;
        samples.push_back(Add(t[0], Add(Scale(Sub(t[1], t[0]), v), Scale(Sub(t[2], t[0]), w))));
      }
    }
    for (int k = 0; k < 3; ++k) {
      for (int i = 0; i <= kEdgeGrid; ++i) {
        const double s = double(i) / kEdgeGrid;
        samples.push_back(Add(Scale(t[k], 1 - s), Scale(t[(k + 1) % 3], s)));
      }
    }
    for (int n = 0; n < 60; ++n) {
      Vec3 p = {uniform(rng), uniform(rng), uniform(rng)};
      if (n % 4 == 0) p[2] = t[0][2];  // in or near the plane of the first two triangles
      const TriangleClosestPoint c = ClosestPointOnTriangle(p, t[0], t[1], t[2]);
      // A point of the triangle, described consistently by point, bary and distance2.
      EXPECT_GE(c.bary[0], 0);
      EXPECT_GE(c.bary[1], 0);
      EXPECT_GE(c.bary[2], 0);
      EXPECT_NEAR(c.bary[0] + c.bary[1] + c.bary[2], 1, 1e-14);
      const Vec3 from_bary =
          Add(Add(Scale(t[0], c.bary[0]), Scale(t[1], c.bary[1])), Scale(t[2], c.bary[2]));
      EXPECT_LT(Norm(Sub(from_bary, c.point)), 1e-13);
      const double d = std::sqrt(c.distance2);
      EXPECT_NEAR(d, Norm(Sub(p, c.point)), 1e-14);
      // No sample is closer, and the sampling gets as close as its spacing allows.
      double sampled = kInf;
      for (const Vec3& s : samples) sampled = std::min(sampled, Norm(Sub(p, s)));
      EXPECT_GE(sampled, d - 1e-13) << "triangle " << &t - &triangles[0] << " query " << n;
      EXPECT_LE(sampled, d + 2 * longest / kGrid) << "triangle " << &t - &triangles[0];
    }
  }
}

TEST(ClosestPointOnTriangleTest, VertexQueriesReturnTheVertexExactly) {
  const Vec3 a = {0.1, 0.2, 0.3}, b = {1.3, 0.1, -0.2}, c = {0.4, 0.9, 0.5};
  const std::array<Vec3, 3> corners = {a, b, c};
  for (int k = 0; k < 3; ++k) {
    const TriangleClosestPoint r = ClosestPointOnTriangle(corners[k], a, b, c);
    EXPECT_EQ(r.distance2, 0);
    EXPECT_EQ(r.point, corners[k]);
    EXPECT_EQ(r.bary[k], 1);
  }
}

// ------------------------------------------------------------------------------------------
// Against the brute-force scan on committed meshes.

class LocateBruteForceTest : public testing::TestWithParam<std::string> {};

TEST_P(LocateBruteForceTest, MatchesBruteForce) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok()) << data.status();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  EXPECT_GT(locator.MemoryBytes(), 0u);
  const double diagonal = BoxDiagonal(*mesh);

  std::mt19937_64 rng(7);
  std::vector<Vec3> queries;
  // Random points in the bounding box grown by a quarter of its diagonal on every side.
  for (int a = 0; a < 3; ++a) ASSERT_LT(mesh->BoundsMin()[a], mesh->BoundsMax()[a]);
  std::array<std::uniform_real_distribution<double>, 3> axis;
  for (int a = 0; a < 3; ++a) {
    axis[a] = std::uniform_real_distribution<double>(mesh->BoundsMin()[a] - 0.25 * diagonal,
                                                     mesh->BoundsMax()[a] + 0.25 * diagonal);
  }
  for (int n = 0; n < 2000; ++n) queries.push_back({axis[0](rng), axis[1](rng), axis[2](rng)});
  // And points very close to the surface, where many faces nearly tie.
  std::uniform_int_distribution<uint32_t> face(0, mesh->face_count() - 1);
  std::uniform_real_distribution<double> unit(0, 1), offset(-1e-3, 1e-3);
  for (int n = 0; n < 500; ++n) {
    const uint32_t f = face(rng);
    double b1 = unit(rng), b2 = unit(rng);
    if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
    const Vec3 p = FacePoint(*data, f, {1 - b1 - b2, b1, b2});
    queries.push_back(Add(p, Scale({offset(rng), offset(rng), offset(rng)}, diagonal)));
  }

  for (size_t n = 0; n < queries.size(); ++n) {
    const Vec3& xyz = queries[n];
    absl::StatusOr<LocatedPoint> located = locator.Locate(xyz);
    ASSERT_TRUE(located.ok()) << located.status();
    const BruteResult brute = BruteForce(*mesh, xyz);
    ASSERT_LE(std::abs(located->distance - brute.distance), 1e-12 * brute.distance)
        << "query " << n << ": locate " << located->distance << " brute " << brute.distance;
    EXPECT_LT(Norm(Sub(located->position, brute.position)), 1e-12 * diagonal) << "query " << n;
    EXPECT_NEAR(Norm(Sub(xyz, located->position)), located->distance, 1e-12 * diagonal);
    // The surface point means the reported position (snapping moves it by < 1e-12 of an edge).
    EXPECT_LT(Norm(Sub(PointPosition(*data, located->point), located->position)), 1e-10 * diagonal)
        << "query " << n << ": " << SurfacePointToString(located->point);
    EXPECT_TRUE(ValidateSurfacePoint(*mesh, located->point).ok());
    if (located->point.kind == SurfacePoint::Kind::kFace) {
      EXPECT_EQ(located->point.face, brute.face) << "query " << n;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(CommittedMeshes, LocateBruteForceTest,
                         testing::Values("kitten.off", "three-peaks.off"),
                         [](const testing::TestParamInfo<std::string>& info) {
                           return info.param == "kitten.off" ? "kitten" : "three_peaks";
                         });

TEST(LocateTest, ConcurrentQueriesAgree) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("kitten.off");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<Vec3> queries(4000);
  const double diagonal = BoxDiagonal(*mesh);
  for (Vec3& q : queries) {
    for (int a = 0; a < 3; ++a) q[a] = mesh->Center()[a] + unit(rng) * diagonal;
  }
  std::vector<double> serial(queries.size());
  for (size_t i = 0; i < queries.size(); ++i) serial[i] = locator.Locate(queries[i])->distance;
  constexpr int kThreads = 4;
  std::vector<std::vector<double>> parallel(kThreads, std::vector<double>(queries.size()));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (size_t i = 0; i < queries.size(); ++i) {
        parallel[t][i] = locator.Locate(queries[i])->distance;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(parallel[t], serial);
}

// ------------------------------------------------------------------------------------------
// Vertices, edges and face interiors.

// A jittered grid with alternating diagonals, tilted out of the coordinate planes.
MeshData TiltedGrid() {
  GridSpec spec;
  spec.cells_x = 6;
  spec.cells_y = 5;
  spec.width = 3;
  spec.height = 2;
  spec.alternate_diagonals = true;
  spec.jitter = 0.15;
  MeshData data = MakeGrid(spec);
  ApplyRigidMotion(&data, {1, 2, 3}, 0.7, {0.5, -1.25, 2});
  return data;
}

TEST(LocateTest, VertexQueriesSnapToTheVertex) {
  const MeshData data = TiltedGrid();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  for (uint32_t v = 0; v < data.vertex_count(); ++v) {
    absl::StatusOr<LocatedPoint> located = locator.Locate(VertexPosition(data, v));
    ASSERT_TRUE(located.ok()) << located.status();
    EXPECT_EQ(located->point.kind, SurfacePoint::Kind::kVertex) << v;
    EXPECT_EQ(located->point.vertex, v);
    EXPECT_EQ(located->distance, 0);
    // Exact up to the round trip through recentred coordinates, (x - c) + c.
    EXPECT_LT(Norm(Sub(located->position, VertexPosition(data, v))), 1e-15);
  }
}

TEST(LocateTest, VertexQueriesOnKitten) {
  absl::StatusOr<MeshData> data = LoadTestMeshData("kitten.off");
  ASSERT_TRUE(data.ok()) << data.status();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  for (uint32_t f = 0; f < mesh->face_count(); f += 37) {
    if (mesh->FaceDegenerate(f)) continue;
    const uint32_t v = data->faces[3 * f + f % 3];
    absl::StatusOr<LocatedPoint> located = locator.Locate(VertexPosition(*data, v));
    ASSERT_TRUE(located.ok()) << located.status();
    ASSERT_EQ(located->point.kind, SurfacePoint::Kind::kVertex) << v;
    EXPECT_EQ(located->distance, 0);
    // Another file vertex at the very same position would be an equally right answer.
    EXPECT_EQ(VertexPosition(*data, located->point.vertex), VertexPosition(*data, v));
  }
}

TEST(LocateTest, EdgeMidpointsSnapToTheEdge) {
  const MeshData data = TiltedGrid();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = data.faces[3 * f + k], b = data.faces[3 * f + (k + 1) % 3];
      const Vec3 mid = Scale(Add(VertexPosition(data, a), VertexPosition(data, b)), 0.5);
      absl::StatusOr<LocatedPoint> located = locator.Locate(mid);
      ASSERT_TRUE(located.ok()) << located.status();
      const SurfacePoint& p = located->point;
      ASSERT_EQ(p.kind, SurfacePoint::Kind::kEdge) << SurfacePointToString(p);
      EXPECT_TRUE((p.edge_from == a && p.edge_to == b) || (p.edge_from == b && p.edge_to == a))
          << SurfacePointToString(p) << " expected edge " << a << "-" << b;
      EXPECT_NEAR(p.t, 0.5, 1e-12);
      EXPECT_LT(Norm(Sub(located->position, mid)), 1e-14);
      EXPECT_LT(Norm(Sub(PointPosition(data, p), mid)), 1e-14);
      EXPECT_LT(located->distance, 1e-14);
    }
  }
}

TEST(LocateTest, PointsAboveFaceInteriors) {
  const MeshData data = TiltedGrid();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  const Vec3 bary = {0.2, 0.3, 0.5};
  constexpr double kHeight = 0.05;  // well below the cell size: the face below is the nearest
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    const Vec3 a = VertexPosition(data, data.faces[3 * f]);
    const Vec3 normal = Cross(Sub(VertexPosition(data, data.faces[3 * f + 1]), a),
                              Sub(VertexPosition(data, data.faces[3 * f + 2]), a));
    const Vec3 foot = FacePoint(data, f, bary);
    for (double side : {1.0, -1.0}) {
      const Vec3 query = Add(foot, Scale(normal, side * kHeight / Norm(normal)));
      absl::StatusOr<LocatedPoint> located = locator.Locate(query);
      ASSERT_TRUE(located.ok()) << located.status();
      const SurfacePoint& p = located->point;
      ASSERT_EQ(p.kind, SurfacePoint::Kind::kFace) << SurfacePointToString(p);
      EXPECT_EQ(p.face, f);
      EXPECT_NEAR(p.bary[0] + p.bary[1] + p.bary[2], 1, 1e-15);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.bary[k], bary[k], 1e-12);
      EXPECT_NEAR(located->distance, kHeight, 1e-14);
      EXPECT_LT(Norm(Sub(located->position, foot)), 1e-14);
    }
  }
}

// ------------------------------------------------------------------------------------------
// A face that Build flips: barycentrics and edges still follow the file's corner order.

TEST(LocateTest, FlippedFaceUsesFileCornerOrder) {
  // Faces 0 and 1 both run 1 -> 2 along their shared edge, so Build flips face 1.
  const MeshData data =
      Soup({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.3}}, {{0, 1, 2}, {1, 2, 3}});
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_TRUE(mesh->FaceFlipped(1));
  ASSERT_FALSE(mesh->FaceFlipped(0));
  const SurfaceLocator locator(*mesh);

  const Vec3 v1 = VertexPosition(data, 1), v2 = VertexPosition(data, 2),
             v3 = VertexPosition(data, 3);
  const Vec3 normal = Cross(Sub(v2, v1), Sub(v3, v1));
  const Vec3 bary = {0.2, 0.3, 0.5};  // file corners 1, 2, 3
  const Vec3 foot = FacePoint(data, 1, bary);
  const Vec3 query = Add(foot, Scale(normal, 0.01 / Norm(normal)));
  absl::StatusOr<LocatedPoint> located = locator.Locate(query);
  ASSERT_TRUE(located.ok()) << located.status();
  const SurfacePoint& p = located->point;
  ASSERT_EQ(p.kind, SurfacePoint::Kind::kFace) << SurfacePointToString(p);
  EXPECT_EQ(p.face, 1u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.bary[k], bary[k], 1e-14) << k;
  EXPECT_LT(Norm(Sub(PointPosition(data, p), located->position)), 1e-14);
  EXPECT_LT(Norm(Sub(located->position, foot)), 1e-14);
  EXPECT_NEAR(located->distance, 0.01, 1e-15);

  // On the flipped face's own boundary edge 2-3: t measured from the vertex it names first.
  const Vec3 on_edge = Add(Scale(v2, 0.7), Scale(v3, 0.3));
  located = locator.Locate(on_edge);
  ASSERT_TRUE(located.ok()) << located.status();
  ASSERT_EQ(located->point.kind, SurfacePoint::Kind::kEdge) << SurfacePointToString(located->point);
  EXPECT_LT(Norm(Sub(PointPosition(data, located->point), on_edge)), 1e-14)
      << SurfacePointToString(located->point);
  EXPECT_LT(located->distance, 1e-15);
}

// ------------------------------------------------------------------------------------------
// Georeferenced coordinates: recentring keeps the answer exact.

TEST(LocateTest, LargeCoordinatesStayExact) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 10;
  spec.width = spec.height = 100;
  spec.alternate_diagonals = true;
  MeshData data = MakeGrid(spec);
  constexpr double kOffset = 5e6, kZ = 300;
  for (size_t v = 0; v < data.vertex_count(); ++v) {
    data.positions[3 * v] += kOffset;
    data.positions[3 * v + 1] += kOffset;
    data.positions[3 * v + 2] += kZ;
  }
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> planar(-30, 130), height(-20, 20);
  for (int n = 0; n < 1000; ++n) {
    const Vec3 query = {kOffset + planar(rng), kOffset + planar(rng), kZ + height(rng)};
    // The rectangle is planar and convex: the answer is the clamped point. The subtractions
    // below are exact (Sterbenz), so the expectation carries no round-off of its own.
    const double dx = query[0] - kOffset, dy = query[1] - kOffset, dz = query[2] - kZ;
    const double cx = std::clamp(dx, 0.0, 100.0), cy = std::clamp(dy, 0.0, 100.0);
    const Vec3 expected = {kOffset + cx, kOffset + cy, kZ};
    const double expected_distance =
        std::sqrt((dx - cx) * (dx - cx) + (dy - cy) * (dy - cy) + dz * dz);
    absl::StatusOr<LocatedPoint> located = locator.Locate(query);
    ASSERT_TRUE(located.ok()) << located.status();
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(located->position[a], expected[a], 1e-6) << n;
    EXPECT_NEAR(located->distance, expected_distance, 1e-6) << n;
    EXPECT_LT(Norm(Sub(PointPosition(data, located->point), expected)), 1e-6)
        << n << ": " << SurfacePointToString(located->point);
  }
  // A vertex far from the origin is still hit exactly.
  const uint32_t v = 57;
  absl::StatusOr<LocatedPoint> located = locator.Locate(VertexPosition(data, v));
  ASSERT_TRUE(located.ok()) << located.status();
  EXPECT_EQ(located->point.kind, SurfacePoint::Kind::kVertex);
  EXPECT_EQ(located->point.vertex, v);
  EXPECT_EQ(located->distance, 0);
}

// ------------------------------------------------------------------------------------------
// Errors.

TEST(LocateTest, NonFiniteInputIsInvalidArgument) {
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(TiltedGrid());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const SurfaceLocator locator(*mesh);
  for (double bad : {kNaN, kInf, -kInf}) {
    for (int a = 0; a < 3; ++a) {
      Vec3 q = {0.5, 0.5, 0.5};
      q[a] = bad;
      EXPECT_EQ(locator.Locate(q).status().code(), absl::StatusCode::kInvalidArgument)
          << bad << " at " << a;
    }
  }
  // Finite but so far away that squared distances would overflow.
  EXPECT_EQ(locator.Locate({1e200, 0, 0}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(locator.Locate({1.7e308, -1.7e308, 0}).status().code(),
            absl::StatusCode::kInvalidArgument);
  // Far but representable is fine.
  absl::StatusOr<LocatedPoint> far = locator.Locate({1e100, 0, 0});
  ASSERT_TRUE(far.ok()) << far.status();
  EXPECT_GT(far->distance, 0.99e100);
}

TEST(LocateTest, OnlyDegenerateFacesIsFailedPrecondition) {
  const MeshData data = Soup({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}});
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_TRUE(mesh->FaceDegenerate(0));
  const SurfaceLocator locator(*mesh);
  EXPECT_EQ(locator.Locate({0, 0, 0}).status().code(), absl::StatusCode::kFailedPrecondition);
  // Non-finite input is still reported as such.
  EXPECT_EQ(locator.Locate({kNaN, 0, 0}).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace geodex
