// ICH against closed-form geodesic distances on meshes whose exact answer is known analytically
// (tests/util/mesh_factory.h derives each one), and Dijkstra against hand-computed edge paths.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"

namespace geodex {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Exactness tolerance: relative to the largest finite distance of the field.
constexpr double kRelTol = 1e-10;

absl::StatusOr<DistanceField> Solve(const MeshData& data, const std::vector<SurfacePoint>& sources,
                                    const GeodesicOptions& options = {}) {
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  if (!mesh.ok()) return mesh.status();
  return ComputeDistanceField(*mesh, sources, options);
}

// Checks `field` against `exact` at every vertex: |d - exact| <= 1e-10 * max finite exact, labels
// equal to `labels` (or all 0 when empty). Prints the max error so the report shows the margin.
void ExpectMatchesExact(const std::string& what, const DistanceField& field,
                        const std::vector<double>& exact,
                        const std::vector<uint32_t>& labels = {}) {
  ASSERT_EQ(field.distance.size(), exact.size()) << what;
  ASSERT_EQ(field.source.size(), exact.size()) << what;
  double max_exact = 0;
  for (double e : exact) {
    if (std::isfinite(e)) max_exact = std::max(max_exact, e);
  }
  const double tol = kRelTol * max_exact;
  double max_err = 0;
  int reported = 0;
  for (size_t v = 0; v < exact.size(); ++v) {
    const double d = field.distance[v];
    const double err = std::abs(d - exact[v]);
    if (!(err <= tol)) {  // also catches NaN
      if (++reported <= 8) {
        ADD_FAILURE() << what << ": vertex " << v << ": got " << d << ", exact " << exact[v]
                      << " (error " << err << ", tolerance " << tol << ")";
      }
    }
    if (std::isfinite(err)) max_err = std::max(max_err, err);
    const uint32_t want = labels.empty() ? 0u : labels[v];
    if (want != 0xffffffffu && field.source[v] != want && ++reported <= 8) {
      ADD_FAILURE() << what << ": vertex " << v << ": source label " << field.source[v]
                    << ", expected " << want;
    }
  }
  EXPECT_EQ(reported, 0) << what << ": " << reported << " mismatches in total";
  std::printf("[ analytic ] %-44s V=%5zu max|ich-exact| = %.3e (rel %.3e)\n", what.c_str(),
              exact.size(), max_err, max_exact > 0 ? max_err / max_exact : 0.0);
}

uint32_t NearestVertex(const MeshData& m, const Vec3& p) {
  uint32_t best = 0;
  for (uint32_t v = 1; v < m.vertex_count(); ++v) {
    if (Distance3(VertexPosition(m, v), p) < Distance3(VertexPosition(m, best), p)) best = v;
  }
  return best;
}

std::vector<double> EuclideanFrom(const MeshData& m, const Vec3& p) {
  std::vector<double> d(m.vertex_count());
  for (uint32_t v = 0; v < m.vertex_count(); ++v) d[v] = Distance3(p, VertexPosition(m, v));
  return d;
}

Vec3 Lerp(const Vec3& a, const Vec3& b, double t) {
  return {(1 - t) * a[0] + t * b[0], (1 - t) * a[1] + t * b[1], (1 - t) * a[2] + t * b[2]};
}

// A planar mesh moved to a generic position (off z = 0, rotated about a skew axis), so no
// coordinate is special; Euclidean distances are computed after the move.
MeshData Generic(MeshData m) {
  ApplyRigidMotion(&m, {0.3, -0.5, 0.8}, 0.7, {10.25, -3.5, 2.0});
  return m;
}

// ------------------------------------------------------------------------------------------------
// Flat convex domains: geodesic = Euclidean.

TEST(AnalyticTest, FlatGridDistancesAreEuclidean) {
  GridSpec spec;
  spec.cells_x = 16;
  spec.cells_y = 12;
  spec.width = 1.6;
  spec.height = 1.2;
  const MeshData m = Generic(MakeGrid(spec));
  const uint32_t corner = 0, interior = 5 * 17 + 7, edge_mid = 8;
  for (uint32_t s : {corner, interior, edge_mid}) {
    absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("flat grid, source " + std::to_string(s), *f,
                       EuclideanFrom(m, VertexPosition(m, s)));
  }
}

TEST(AnalyticTest, JitteredGridWithAlternatingDiagonalsDistancesAreEuclidean) {
  GridSpec spec;
  spec.cells_x = 18;
  spec.cells_y = 14;
  spec.width = 1.8;
  spec.height = 1.0;
  spec.alternate_diagonals = true;
  spec.jitter = 0.2;
  spec.seed = 42;
  const MeshData m = Generic(MakeGrid(spec));
  for (uint32_t s : {0u, 7u * 19u + 9u, 19u * 15u - 1u}) {
    absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("jittered grid, source " + std::to_string(s), *f,
                       EuclideanFrom(m, VertexPosition(m, s)));
  }
}

TEST(AnalyticTest, EdgeAndFacePointSourcesOnFlatGridGiveEuclideanDistances) {
  GridSpec spec;
  spec.cells_x = 12;
  spec.cells_y = 10;
  spec.alternate_diagonals = true;
  spec.jitter = 0.15;
  const MeshData m = Generic(MakeGrid(spec));
  const uint32_t a = 4 * 13 + 5, b = a + 1;  // an interior horizontal edge
  {
    const Vec3 p = Lerp(VertexPosition(m, a), VertexPosition(m, b), 0.3);
    absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::OnEdge(a, b, 0.3)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("flat grid, interior edge point", *f, EuclideanFrom(m, p));
  }
  {
    // Boundary edge 2-3 (on y = 0), named backwards.
    const Vec3 p = Lerp(VertexPosition(m, 3), VertexPosition(m, 2), 0.75);
    absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::OnEdge(3, 2, 0.75)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("flat grid, boundary edge point", *f, EuclideanFrom(m, p));
  }
  const uint32_t face = 101;
  const double w[3] = {0.2, 0.5, 0.3};
  Vec3 q{};
  for (int k = 0; k < 3; ++k) {
    const Vec3 c = VertexPosition(m, m.faces[3 * face + k]);
    for (int x = 0; x < 3; ++x) q[x] += w[k] * c[x];
  }
  {
    absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::InFace(face, w[0], w[1], w[2])});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("flat grid, face point", *f, EuclideanFrom(m, q));
  }
  {
    // Face point plus a vertex: the minimum of both, labelled by the nearer one.
    const uint32_t v = 140;
    absl::StatusOr<DistanceField> f =
        Solve(m, {SurfacePoint::InFace(face, w[0], w[1], w[2]), SurfacePoint::AtVertex(v)});
    ASSERT_TRUE(f.ok()) << f.status();
    const std::vector<double> d0 = EuclideanFrom(m, q), d1 = EuclideanFrom(m, VertexPosition(m, v));
    std::vector<double> exact(d0.size());
    std::vector<uint32_t> labels(d0.size());
    for (size_t i = 0; i < d0.size(); ++i) {
      exact[i] = std::min(d0[i], d1[i]);
      // Near-ties accept either label.
      labels[i] = std::abs(d0[i] - d1[i]) <= 1e-9 ? 0xffffffffu : (d0[i] < d1[i] ? 0u : 1u);
    }
    ExpectMatchesExact("flat grid, face point + vertex", *f, exact, labels);
  }
}

// ------------------------------------------------------------------------------------------------
// L-shape: shortest paths bend at the reflex corner, a boundary vertex (a boundary pseudo-source).

void CheckLShape(const std::string& what, double jitter) {
  const double size = 2;
  const MeshData flat = MakeLShape(8, size, jitter, 3);
  const MeshData m = Generic(flat);
  // Sources in the upper arm, the right arm, and near the corner of the L.
  for (const Vec3& at : {Vec3{0.25, 1.75, 0}, Vec3{1.875, 0.125, 0}, Vec3{0.5, 0.5, 0}}) {
    const uint32_t s = NearestVertex(flat, at);
    const Vec3 sp = VertexPosition(flat, s);
    std::vector<double> exact(flat.vertex_count());
    int bent = 0;
    for (uint32_t v = 0; v < flat.vertex_count(); ++v) {
      const Vec3 tp = VertexPosition(flat, v);
      exact[v] = LShapeDistance(size, {sp[0], sp[1]}, {tp[0], tp[1]});
      if (exact[v] > Distance3(sp, tp) + 1e-9) ++bent;
    }
    // From the arms, many targets are hidden behind the reflex corner.
    if (at[0] != 0.5) {
      EXPECT_GT(bent, 20) << "test setup: too few paths bend at the reflex corner";
    }
    absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact(
        what + ", source " + std::to_string(s) + " (" + std::to_string(bent) + " bent)", *f, exact);
  }
}

TEST(AnalyticTest, LShapePathsBendAtReflexBoundaryCorner) { CheckLShape("L-shape", 0); }

TEST(AnalyticTest, JitteredLShapePathsBendAtReflexBoundaryCorner) {
  CheckLShape("jittered L-shape", 0.2);
}

// ------------------------------------------------------------------------------------------------
// Cube: exact distances by unfolding (convex, corners of angle 3 pi / 2, never bent at).

TEST(AnalyticTest, CubeDistancesMatchUnfoldings) {
  const double side = 2;
  const MeshData m = MakeCube(6, side);
  const uint32_t corner = 0;                                      // (0, 0, 0)
  const uint32_t top_centre = NearestVertex(m, {1, 1, 2});        // a face centre
  const uint32_t edge_point = NearestVertex(m, {2, 1.0 / 3, 0});  // on an edge of the cube
  const uint32_t off_centre = NearestVertex(m, {2, 2.0 / 3, 4.0 / 3});
  ASSERT_LT(Distance3(VertexPosition(m, top_centre), {1, 1, 2}), 1e-15);
  for (uint32_t s : {corner, top_centre, edge_point, off_centre}) {
    std::vector<double> exact(m.vertex_count());
    for (uint32_t v = 0; v < m.vertex_count(); ++v) {
      exact[v] = CubeDistance(side, VertexPosition(m, s), VertexPosition(m, v));
    }
    absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("cube 6x6, source " + std::to_string(s), *f, exact);
  }
  // Hand-checkable values: corner to the opposite corner is sqrt(side^2 + (2 side)^2); face
  // centre to the opposite face centre is 2 side.
  absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::AtVertex(corner)});
  ASSERT_TRUE(f.ok());
  const uint32_t far_corner = NearestVertex(m, {2, 2, 2});
  EXPECT_NEAR(f->distance[far_corner], std::sqrt(20.0), 1e-12);
  f = Solve(m, {SurfacePoint::AtVertex(top_centre)});
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(f->distance[NearestVertex(m, {1, 1, 0})], 4.0, 1e-12);
}

// ------------------------------------------------------------------------------------------------
// Cones: flat except at the apex.

TEST(AnalyticTest, ConvexConeDistancesMatchUnfolding) {
  const int segments = 12, rings = 6;
  const Cone cone = MakeCone(segments, rings, 1.0, 0.8, /*saddle=*/false);
  ASSERT_LT(cone.total_angle, 2 * kPi);
  const uint32_t apex = 0, rim = 1 + (rings - 1) * segments, inner = 1 + 2 * segments + 5;
  for (uint32_t s : {apex, rim, inner}) {
    std::vector<double> exact(cone.data.vertex_count());
    for (uint32_t v = 0; v < exact.size(); ++v) exact[v] = ConeDistance(cone, s, v);
    absl::StatusOr<DistanceField> f = Solve(cone.data, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("convex cone, source " + std::to_string(s), *f, exact);
  }
}

// The wavy disk's apex has angle sum Theta > 2 pi. Unfolded around the apex, two points whose
// angular separation (the shorter way round) is >= pi see each other through no straight segment,
// so the shortest path runs into the apex and out again: d = rho_a + rho_b. In particular a rim
// vertex and the rim vertex on the opposite generator (separation Theta / 2 > pi) are exactly
// 2 * slant apart, although they are much closer in space.
TEST(AnalyticTest, SaddleApexPathsBendAtApex) {
  const int segments = 12, rings = 6;
  const double slant = 1.0;
  const Cone cone = MakeCone(segments, rings, slant, 0.5, /*saddle=*/true);
  ASSERT_GT(cone.total_angle, 2 * kPi + 1);
  const uint32_t rim0 = 1 + (rings - 1) * segments;  // ring `rings`, generator 0
  const uint32_t inner = 1 + 2 * segments + 3;
  for (uint32_t s : {rim0, inner, 0u}) {
    std::vector<double> exact(cone.data.vertex_count());
    int through_apex = 0;
    for (uint32_t v = 0; v < exact.size(); ++v) {
      exact[v] = ConeDistance(cone, s, v);
      if (v != 0 && s != 0 && exact[v] == cone.rho[s] + cone.rho[v]) ++through_apex;
    }
    if (s != 0) {
      EXPECT_GT(through_apex, 10) << "test setup: too few paths through the apex";
    }
    absl::StatusOr<DistanceField> f = Solve(cone.data, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("saddle cone, source " + std::to_string(s) + " (" +
                           std::to_string(through_apex) + " via apex)",
                       *f, exact);
  }
  absl::StatusOr<DistanceField> f = Solve(cone.data, {SurfacePoint::AtVertex(rim0)});
  ASSERT_TRUE(f.ok());
  const uint32_t opposite = rim0 + segments / 2;
  EXPECT_NEAR(f->distance[opposite], 2 * slant, 1e-12);
  EXPECT_LT(Distance3(VertexPosition(cone.data, rim0), VertexPosition(cone.data, opposite)),
            1.9 * slant);
}

// ------------------------------------------------------------------------------------------------
// Open cylinder (prism): unrolls onto a periodic strip.

TEST(AnalyticTest, OpenCylinderDistancesMatchUnrolledStrip) {
  const int segments = 16, rings = 10;
  const Cylinder cyl = MakeOpenCylinder(segments, rings, 1.0, 3.0, /*alternate_diagonals=*/true);
  for (uint32_t s : {0u, 5u * segments + 3u, 10u * segments + 15u}) {
    std::vector<double> exact(cyl.data.vertex_count());
    for (uint32_t v = 0; v < exact.size(); ++v) exact[v] = CylinderDistance(cyl, s, v);
    absl::StatusOr<DistanceField> f = Solve(cyl.data, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectMatchesExact("open cylinder, source " + std::to_string(s), *f, exact);
  }
  // Half way round on the same ring: half the perimeter.
  absl::StatusOr<DistanceField> f = Solve(cyl.data, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(f->distance[segments / 2], cyl.perimeter / 2, 1e-12);
}

// ------------------------------------------------------------------------------------------------
// Dijkstra.

// 2 x 2 unit cells, every diagonal from (i, j) to (i+1, j+1); vertex (i, j) has id 3 j + i.
TEST(AnalyticTest, DijkstraEqualsShortestEdgePathOnTinyGrid) {
  GridSpec spec;
  spec.cells_x = 2;
  spec.cells_y = 2;
  spec.width = 2;
  spec.height = 2;
  const MeshData m = MakeGrid(spec);
  GeodesicOptions options;
  options.method = Method::kDijkstra;
  absl::StatusOr<DistanceField> f = Solve(m, {SurfacePoint::AtVertex(0)}, options);
  ASSERT_TRUE(f.ok()) << f.status();
  const double r2 = std::sqrt(2.0);
  // (0,0) (1,0) (2,0) / (0,1) (1,1) (2,1) / (0,2) (1,2) (2,2), by hand: axis steps cost 1, a
  // diagonal step sqrt(2).
  const std::vector<double> expected = {0, 1, 2, 1, r2, 1 + r2, 2, 1 + r2, 2 * r2};
  ASSERT_EQ(f->distance.size(), expected.size());
  for (size_t v = 0; v < expected.size(); ++v) {
    EXPECT_NEAR(f->distance[v], expected[v], 1e-15) << "vertex " << v;
  }
  // From the other diagonal's corner (2, 0) no diagonal helps: Manhattan distances.
  f = Solve(m, {SurfacePoint::AtVertex(2)}, options);
  ASSERT_TRUE(f.ok()) << f.status();
  const std::vector<double> manhattan = {2, 1, 0, 3, 2, 1, 4, 3, 2};
  for (size_t v = 0; v < manhattan.size(); ++v) {
    EXPECT_NEAR(f->distance[v], manhattan[v], 1e-15) << "vertex " << v;
  }
  // ICH on the same mesh: Euclidean, strictly below Dijkstra at (2, 1).
  absl::StatusOr<DistanceField> exact = Solve(m, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(exact.ok());
  EXPECT_NEAR(exact->distance[5], std::sqrt(5.0), 1e-14);
}

TEST(AnalyticTest, DijkstraIsNeverShorterThanExactDistances) {
  GeodesicOptions dijkstra;
  dijkstra.method = Method::kDijkstra;
  struct Case {
    std::string name;
    MeshData mesh;
    uint32_t source = 0;
    std::vector<double> exact;  // from `source`
  };
  std::vector<Case> cases;
  {
    GridSpec spec;
    spec.cells_x = spec.cells_y = 10;
    spec.jitter = 0.2;
    spec.alternate_diagonals = true;
    Case c{"jittered grid", MakeGrid(spec), 0, {}};
    c.exact = EuclideanFrom(c.mesh, VertexPosition(c.mesh, 0));
    cases.push_back(std::move(c));
  }
  {
    Case c{"cube", MakeCube(4, 1.0), 0, {}};
    for (uint32_t v = 0; v < c.mesh.vertex_count(); ++v) {
      c.exact.push_back(CubeDistance(1.0, VertexPosition(c.mesh, 0), VertexPosition(c.mesh, v)));
    }
    cases.push_back(std::move(c));
  }
  {
    const Cone cone = MakeCone(12, 5, 1.0, 0.5, /*saddle=*/true);
    Case c{"saddle cone", cone.data, 1 + 4 * 12, {}};  // a rim vertex
    for (uint32_t v = 0; v < cone.data.vertex_count(); ++v) {
      c.exact.push_back(ConeDistance(cone, c.source, v));
    }
    cases.push_back(std::move(c));
  }
  for (const Case& c : cases) {
    absl::StatusOr<DistanceField> f = Solve(c.mesh, {SurfacePoint::AtVertex(c.source)}, dijkstra);
    ASSERT_TRUE(f.ok()) << f.status();
    ASSERT_EQ(f->distance.size(), c.exact.size());
    int longer = 0;
    for (size_t v = 0; v < c.exact.size(); ++v) {
      EXPECT_GE(f->distance[v], c.exact[v] * (1 - 1e-12)) << c.name << " v " << v;
      if (f->distance[v] > c.exact[v] * (1 + 1e-9)) ++longer;
    }
    EXPECT_GT(longer, 0) << c.name << ": Dijkstra should be strictly longer somewhere";
  }
}

}  // namespace
}  // namespace geodex
