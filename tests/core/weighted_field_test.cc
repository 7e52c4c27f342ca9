// The weighted (travel cost) engine: costs within [true, (1 + epsilon) true] on planes (Euclidean
// and Snell's-law optima), on real meshes (the exact engine), around impassable walls; scaling,
// option errors, limits, cancellation and determinism.

#include "geodex/weighted_field.h"

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/limits.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TriangleMesh BuildMesh(const MeshData& data) {
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return *std::move(mesh);
}

// Every cost within [d (1 - 1e-12), (1 + eps) d] of the reference; returns the largest ratio.
double CheckBound(const std::vector<double>& cost, const std::vector<double>& reference,
                  double eps) {
  double worst = 1;
  for (size_t v = 0; v < cost.size(); ++v) {
    const double d = reference[v];
    if (d == 0) {
      EXPECT_EQ(cost[v], 0) << "vertex " << v;
      continue;
    }
    EXPECT_GE(cost[v], d * (1 - 1e-12)) << "vertex " << v;
    EXPECT_LE(cost[v], d * (1 + eps)) << "vertex " << v;
    worst = std::max(worst, cost[v] / d);
  }
  return worst;
}

// A unit square of cells x cells, its vertices jittered by up to 0.2 of a cell.
MeshData JitteredGrid(uint32_t cells) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = cells;
  spec.jitter = 0.2;
  return MakeGrid(spec);
}

class WeightedFieldPlaneTest : public testing::TestWithParam<double> {};

TEST_P(WeightedFieldPlaneTest, EuclideanOnAGrid) {
  const double eps = GetParam();
  GridSpec spec;
  spec.cells_x = spec.cells_y = eps < 0.05 ? 6 : 12;
  spec.alternate_diagonals = true;
  const MeshData data = MakeGrid(spec);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.epsilon = eps;
  for (const uint32_t s : {0u, static_cast<uint32_t>(data.vertex_count() / 2)}) {
    absl::StatusOr<WeightedField> field =
        ComputeWeightedField(mesh, {SurfacePoint::AtVertex(s)}, options);
    ASSERT_TRUE(field.ok()) << field.status();
    std::vector<double> euclid;
    for (uint32_t v = 0; v < data.vertex_count(); ++v) {
      euclid.push_back(Distance3(VertexPosition(data, s), VertexPosition(data, v)));
    }
    const double worst = CheckBound(field->cost, euclid, eps);
    EXPECT_GT(field->steiner_points, 0u);
    std::printf("eps %g source %u: %llu Steiner points, worst ratio 1 + %.3g\n", eps, s,
                static_cast<unsigned long long>(field->steiner_points), worst - 1);
  }
}

TEST_P(WeightedFieldPlaneTest, TwentyDegreesOffTheAxesOnAJitteredGrid) {
  const double eps = GetParam();
  GridSpec spec;
  spec.cells_x = spec.cells_y = eps < 0.05 ? 6 : 10;
  spec.jitter = 0.15;
  const MeshData data = MakeGrid(spec);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.epsilon = eps;
  // Targets along a ray 20 degrees off the x axis from vertex 0, as face points (located by the
  // test: the face whose barycentrics are all >= 0).
  std::vector<SurfacePoint> targets;
  std::vector<double> expected;
  const double angle = 20 * M_PI / 180;
  for (double r = 0.15; r < 1.0; r += 0.2) {
    const Vec2 p{r * std::cos(angle), r * std::sin(angle)};
    for (uint32_t f = 0; f < data.face_count(); ++f) {
      const Vec3 a = VertexPosition(data, data.faces[3 * f]);
      const Vec3 b = VertexPosition(data, data.faces[3 * f + 1]);
      const Vec3 c = VertexPosition(data, data.faces[3 * f + 2]);
      const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
      const double l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / det;
      const double l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / det;
      if (l1 >= 0 && l2 >= 0 && l1 + l2 <= 1) {
        targets.push_back(SurfacePoint::InFace(f, 1 - l1 - l2, l1, l2));
        expected.push_back(r);
        break;
      }
    }
  }
  ASSERT_EQ(targets.size(), 5u);
  absl::StatusOr<WeightedCosts> costs =
      ComputeWeightedCostsAt(mesh, {SurfacePoint::AtVertex(0)}, targets, options);
  ASSERT_TRUE(costs.ok()) << costs.status();
  CheckBound(costs->cost, expected, eps);
  absl::StatusOr<WeightedField> field =
      ComputeWeightedField(mesh, {SurfacePoint::AtVertex(0)}, options);
  ASSERT_TRUE(field.ok()) << field.status();
  std::vector<double> euclid;
  for (uint32_t v = 0; v < data.vertex_count(); ++v) {
    euclid.push_back(Distance3(VertexPosition(data, 0), VertexPosition(data, v)));
  }
  CheckBound(field->cost, euclid, eps);
}

INSTANTIATE_TEST_SUITE_P(WeightedFieldEpsilons, WeightedFieldPlaneTest, testing::Values(0.1, 0.01));

TEST(WeightedFieldTest, RealMeshesAgainstTheExactEngine) {
  for (const char* name : {"knight.off", "bunny-npm.off"}) {
    absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(name);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    const std::vector<SurfacePoint> sources{SurfacePoint::AtVertex(7)};
    absl::StatusOr<DistanceField> exact = ComputeDistanceField(*mesh, sources);
    ASSERT_TRUE(exact.ok()) << exact.status();
    for (const double eps : {0.1, 0.03}) {
      WeightedOptions options;
      options.epsilon = eps;
      absl::StatusOr<WeightedField> field = ComputeWeightedField(*mesh, sources, options);
      ASSERT_TRUE(field.ok()) << field.status();
      const double worst = CheckBound(field->cost, exact->distance, eps);
      std::printf("%s eps %g: %llu Steiner points, %.0f ms, worst ratio 1 + %.3g\n", name, eps,
                  static_cast<unsigned long long>(field->steiner_points), field->stats.solve_ms,
                  worst - 1);
    }
  }
}

// Face points a hair (delta) from a corner or an edge of each face around `vertex`: near each
// corner, and off each edge at 0.37 of it from its lower-numbered end (not at a Steiner point such
// as the midpoint), so the faces on either side of an edge hold two points facing each other.
std::vector<SurfacePoint> PointsAroundVertex(const MeshData& data, uint32_t vertex, double delta) {
  std::vector<SurfacePoint> out;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    const uint32_t* c = &data.faces[3 * f];
    if (c[0] != vertex && c[1] != vertex && c[2] != vertex) continue;
    for (int k = 0; k < 3; ++k) {
      std::array<double, 3> corner{delta, delta, delta}, edge{0, 0, 0};
      corner[k] = 1 - 2 * delta;
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      edge[k] = (c[k] < c[k1] ? 0.63 : 0.37) * (1 - delta);
      edge[k1] = (c[k] < c[k1] ? 0.37 : 0.63) * (1 - delta);
      edge[k2] = delta;
      out.push_back(SurfacePoint::InFace(f, corner[0], corner[1], corner[2]));
      out.push_back(SurfacePoint::InFace(f, edge[0], edge[1], edge[2]));
    }
  }
  return out;
}

// The bound holds between points strictly inside faces, however close to an edge or a vertex and
// to each other (across an edge, around a corner): the graph is refined around them (Aleksandrov,
// Maheshwari and Sack make such points vertices). Without it, two points 1e-4 apart across an edge
// cost 84 times their distance at epsilon 0.01. Against the Euclidean distance on a plane, and the
// exact engine on a real mesh; through a surface shared by the queries and built without them
// too (it must build one refined around them).
TEST(WeightedFieldTest, PointsNearEdgesAndVerticesKeepTheBound) {
  const MeshData data = JitteredGrid(6);
  const TriangleMesh mesh = BuildMesh(data);
  // (epsilon, delta): the finer epsilon only at one delta (a point a hair from a vertex adds
  // some thousand points there, which its neighbours' links pay for as their square).
  for (const auto& [eps, delta] :
       {std::pair{0.1, 1e-3}, std::pair{0.1, 1e-6}, std::pair{0.01, 1e-4}}) {
    WeightedOptions options;
    options.epsilon = eps;
    const std::vector<SurfacePoint> points = PointsAroundVertex(data, 24, delta);
    // One surface refined around every point (a matrix's), and one around none: a query on it
    // builds its own, as ComputeWeightedCostsAt does.
    absl::StatusOr<WeightedSurface> anchored = WeightedSurface::Build(mesh, options, {}, points);
    absl::StatusOr<WeightedSurface> bare = WeightedSurface::Build(mesh, options);
    ASSERT_TRUE(anchored.ok() && bare.ok()) << anchored.status() << bare.status();
    double worst = 1;
    // Every third point as a source (a search on the refined graph costs some 0.2 s here), to every
    // point.
    for (size_t i = 0; i < points.size(); i += 3) {
      std::vector<double> euclid;
      for (const SurfacePoint& p : points) {
        euclid.push_back(Distance3(PositionOf(data, points[i]), PositionOf(data, p)));
      }
      absl::StatusOr<WeightedCosts> costs = anchored->CostsAt({points[i]}, points);
      ASSERT_TRUE(costs.ok()) << costs.status();
      worst = std::max(worst, CheckBound(costs->cost, euclid, eps));
      if (i % 9 == 0) {
        const std::vector<SurfacePoint> pair = {points[(i + 7) % points.size()]};
        absl::StatusOr<WeightedCosts> fresh =
            ComputeWeightedCostsAt(mesh, {points[i]}, pair, options);
        absl::StatusOr<WeightedCosts> on_bare = bare->CostsAt({points[i]}, pair);
        ASSERT_TRUE(fresh.ok() && on_bare.ok()) << fresh.status() << on_bare.status();
        EXPECT_EQ(on_bare->cost, fresh->cost) << i;
        CheckBound(fresh->cost, {euclid[(i + 7) % points.size()]}, eps);
      }
    }
    std::printf("plane, eps %g, delta %g: worst ratio 1 + %.3g\n", eps, delta, worst - 1);
  }

  // The anchors' points count against the Steiner-point limit, and a tiny epsilon (progressions
  // of factor next to 1) meets the limit rather than a loop that never ends.
  {
    const std::vector<SurfacePoint> points = PointsAroundVertex(data, 24, 1e-6);
    WeightedOptions options;
    options.epsilon = 0.1;
    absl::StatusOr<WeightedSurface> bare = WeightedSurface::Build(mesh, options);
    ASSERT_TRUE(bare.ok()) << bare.status();
    options.max_steiner_points = bare->steiner_points() + 10;
    EXPECT_TRUE(WeightedSurface::Build(mesh, options).ok());
    absl::Status over = WeightedSurface::Build(mesh, options, {}, points).status();
    EXPECT_TRUE(absl::IsResourceExhausted(over)) << over;
    options.epsilon = 1e-12;
    options.max_steiner_points = 0;
    over = WeightedSurface::Build(mesh, options, {}, points).status();
    EXPECT_TRUE(absl::IsResourceExhausted(over)) << over;
  }

  absl::StatusOr<TriangleMesh> knight = LoadTestMesh("knight.off");
  ASSERT_TRUE(knight.ok()) << knight.status();
  const MeshData knight_data = knight->ToMeshData();
  const std::vector<SurfacePoint> points = PointsAroundVertex(knight_data, 100, 1e-5);
  absl::StatusOr<DistanceMatrix> exact =
      ComputeDistanceMatrix(*knight, points, points, GeodesicOptions{});
  ASSERT_TRUE(exact.ok()) << exact.status();
  WeightedOptions options;
  options.epsilon = 0.03;
  absl::StatusOr<WeightedSurface> surface =
      WeightedSurface::Build(*knight, options, points, points);
  ASSERT_TRUE(surface.ok()) << surface.status();
  double worst = 1;
  for (size_t i = 0; i < points.size(); i += 3) {
    absl::StatusOr<WeightedCosts> costs = surface->CostsAt({points[i]}, points);
    ASSERT_TRUE(costs.ok()) << costs.status();
    const std::vector<double> row(exact->values.begin() + i * points.size(),
                                  exact->values.begin() + (i + 1) * points.size());
    worst = std::max(worst, CheckBound(costs->cost, row, options.epsilon));
  }
  std::printf("knight, %zu points, eps 0.03: worst ratio 1 + %.3g\n", points.size(), worst - 1);
}

// Targets covering the surface (a raster's cells on a TIN) are not anchors: the graph stays the
// one built around the sources (hundreds of points per cell would not fit), and its times are at
// least those of the graph refined around every target (a superset of its nodes).
TEST(WeightedFieldTest, TargetsCoveringTheSurfaceAreNotAnchors) {
  const MeshData data = JitteredGrid(6);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.epsilon = 0.1;
  const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(24)};
  std::vector<SurfacePoint> cells;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    cells.push_back(SurfacePoint::InFace(f, 0.2, 0.3, 0.5));
  }
  absl::StatusOr<WeightedSurface> surface = WeightedSurface::Build(mesh, options, sources);
  ASSERT_TRUE(surface.ok()) << surface.status();
  WeightedSurface::Limits limits;
  limits.anchor_targets = false;
  absl::StatusOr<WeightedCosts> raster = surface->CostsAt(sources, cells, true, limits);
  absl::StatusOr<WeightedCosts> anchored = ComputeWeightedCostsAt(mesh, sources, cells, options);
  ASSERT_TRUE(raster.ok() && anchored.ok()) << raster.status() << anchored.status();
  EXPECT_EQ(raster->steiner_points, surface->steiner_points());
  EXPECT_GT(anchored->steiner_points, raster->steiner_points);
  for (size_t c = 0; c < cells.size(); ++c) {
    EXPECT_LE(anchored->cost[c], raster->cost[c]) << c;
    const double euclid = Distance3(VertexPosition(data, 24), PositionOf(data, cells[c]));
    EXPECT_GE(raster->cost[c], euclid * (1 - 1e-12)) << c;
  }
}

TEST(WeightedFieldTest, FrictionTwoDoublesEveryCost) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  WeightedOptions one, two;
  one.epsilon = two.epsilon = 0.1;
  two.face_weight.assign(mesh->face_count(), 2.0);
  const std::vector<SurfacePoint> sources{SurfacePoint::AtVertex(3),
                                          SurfacePoint::InFace(100, 0.2, 0.3, 0.5)};
  absl::StatusOr<WeightedField> a = ComputeWeightedField(*mesh, sources, one);
  absl::StatusOr<WeightedField> b = ComputeWeightedField(*mesh, sources, two);
  ASSERT_TRUE(a.ok() && b.ok());
  for (size_t v = 0; v < a->cost.size(); ++v) {
    EXPECT_EQ(b->cost[v], 2 * a->cost[v]) << "vertex " << v;
    EXPECT_EQ(b->source[v], a->source[v]) << "vertex " << v;
  }
}

TEST(WeightedFieldTest, SnellsLawAcrossAFrictionFourHalfPlane) {
  GridSpec spec;
  spec.cells_x = 10;
  spec.cells_y = 5;
  spec.width = 2;
  spec.height = 1;
  spec.alternate_diagonals = true;
  const MeshData data = MakeGrid(spec);
  const TriangleMesh mesh = BuildMesh(data);
  const double eps = 0.03;
  WeightedOptions options;
  options.epsilon = eps;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    options.face_weight.push_back(FaceCentroid(data, f)[0] > 1 ? 4.0 : 1.0);
  }
  const uint32_t s = 1 * 11 + 1, t = 4 * 11 + 8;  // (0.2, 0.2) and (1.6, 0.8)
  const Vec3 ps = VertexPosition(data, s), pt = VertexPosition(data, t);
  auto cost = [&](double y) {
    return std::hypot(1 - ps[0], y - ps[1]) + 4 * std::hypot(pt[0] - 1, pt[1] - y);
  };
  const double y_best = GoldenSectionArgMin(cost, 0, 1);
  const double best = cost(y_best);
  absl::StatusOr<WeightedPath> path =
      ComputeWeightedPath(mesh, SurfacePoint::AtVertex(s), SurfacePoint::AtVertex(t), options);
  ASSERT_TRUE(path.ok()) << path.status();
  EXPECT_GE(path->cost, best * (1 - 1e-12));
  EXPECT_LE(path->cost, best * (1 + eps));
  // The polyline costs what the engine says, and crosses x = 1 near the optimum.
  ASSERT_GE(path->points.size(), 2u);
  EXPECT_EQ(path->points.front().where.vertex, s);
  EXPECT_EQ(path->points.back().where.vertex, t);
  double sum = 0, y_cross = -1;
  for (size_t i = 0; i + 1 < path->points.size(); ++i) {
    const auto& a = path->points[i].position;
    const auto& b = path->points[i + 1].position;
    const double mid = (a[0] + b[0]) / 2;
    const bool along_boundary = std::abs(a[0] - 1) < 1e-12 && std::abs(b[0] - 1) < 1e-12;
    sum +=
        (along_boundary || mid < 1 ? 1.0 : 4.0) * Distance3({a[0], a[1], a[2]}, {b[0], b[1], b[2]});
    if (std::abs(a[0] - 1) < 1e-12 && y_cross < 0) y_cross = a[1];
  }
  EXPECT_NEAR(sum, path->cost, 1e-12 * path->cost);
  EXPECT_NEAR(y_cross, y_best, 0.05);
  std::printf("Snell: optimum %.6f at y %.4f, engine %.6f (1 + %.3g), crossing y %.4f\n", best,
              y_best, path->cost, path->cost / best - 1, y_cross);
}

TEST(WeightedFieldTest, ImpassableWallIsGoneAroundThroughItsGap) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 20;
  const MeshData data = MakeGrid(spec);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.epsilon = 0.05;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    const Vec3 c = FaceCentroid(data, f);
    const bool wall = c[0] > 0.45 && c[0] < 0.55 && c[1] < 0.8;
    options.face_weight.push_back(wall ? kInf : 1.0);
  }
  const uint32_t s = 4 * 21 + 4, t = 4 * 21 + 16;  // (0.2, 0.2) and (0.8, 0.2)
  const double detour = 2 * 0.65 + 0.1;            // via (0.45, 0.8) and (0.55, 0.8)
  absl::StatusOr<WeightedCosts> costs = ComputeWeightedCostsAt(
      mesh, {SurfacePoint::AtVertex(s)}, {SurfacePoint::AtVertex(t)}, options);
  ASSERT_TRUE(costs.ok()) << costs.status();
  EXPECT_GE(costs->cost[0], detour * (1 - 1e-12));
  EXPECT_LE(costs->cost[0], detour * (1 + options.epsilon));
  absl::StatusOr<WeightedPath> path =
      ComputeWeightedPath(mesh, SurfacePoint::AtVertex(s), SurfacePoint::AtVertex(t), options);
  ASSERT_TRUE(path.ok()) << path.status();
  EXPECT_EQ(path->cost, costs->cost[0]);
  for (const PathPoint& p : path->points) {
    const bool inside =
        p.position[0] > 0.45 + 1e-12 && p.position[0] < 0.55 - 1e-12 && p.position[1] < 0.8 - 1e-12;
    EXPECT_FALSE(inside) << p.position[0] << " " << p.position[1];
  }
}

// On a 20 x 20 grid of the unit square: weight +inf on the faces of the border cells of the
// square of cells [lo, hi]^2, 1 elsewhere.
std::vector<double> RingWeights(const MeshData& data, int lo, int hi) {
  std::vector<double> w;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    const Vec3 c = FaceCentroid(data, f);
    const int i = static_cast<int>(c[0] * 20), j = static_cast<int>(c[1] * 20);
    const bool ring =
        i >= lo && i <= hi && j >= lo && j <= hi && (i == lo || i == hi || j == lo || j == hi);
    w.push_back(ring ? kInf : 1.0);
  }
  return w;
}

TEST(WeightedFieldTest, EnclosedRegionIsUnreachable) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 20;
  const MeshData data = MakeGrid(spec);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.epsilon = 0.1;
  options.face_weight = RingWeights(data, 5, 14);
  absl::StatusOr<WeightedField> field =
      ComputeWeightedField(mesh, {SurfacePoint::AtVertex(10 * 21 + 10)}, options);
  ASSERT_TRUE(field.ok()) << field.status();
  EXPECT_EQ(field->cost[0], kInf);
  EXPECT_EQ(field->source[0], 0xffffffffu);
  EXPECT_LT(field->cost[8 * 21 + 8], kInf);
  absl::StatusOr<WeightedPath> path = ComputeWeightedPath(
      mesh, SurfacePoint::AtVertex(10 * 21 + 10), SurfacePoint::AtVertex(0), options);
  EXPECT_EQ(path.status().code(), absl::StatusCode::kNotFound);
}

// The search's own certificate: after it, no graph link lowers any node's cost (Bellman's
// condition), so it settled the graph's least costs, not merely costs within the bound. Checked on
// a real mesh and a jittered grid, with and without friction (a ring wall and weights 1 to 4), with
// a direction-dependent cost, from several vertex, edge and face sources. It catches what the
// bound cannot: a queue that settles a node before its best link arrived still lands within
// (1 + epsilon) most of the time.
TEST(WeightedFieldTest, SearchSettlesTheGraphsLeastCosts) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 20;
  spec.jitter = 0.2;
  const MeshData grid = MakeGrid(spec);
  absl::StatusOr<MeshData> knight = LoadTestMeshData("knight.off");
  ASSERT_TRUE(knight.ok()) << knight.status();
  // A slope cost that differs up and down and by steepness (any positive samples do).
  auto slope = std::make_shared<SlopeCost>();
  for (int i = 0; i <= 64; ++i) {
    const double sine = -1 + i / 32.0;
    slope->per_metre.push_back(1 + 3 * std::max(0.0, sine) + 0.5 * sine * sine);
  }
  for (const MeshData* data : {&grid, static_cast<const MeshData*>(&*knight)}) {
    const TriangleMesh mesh = BuildMesh(*data);
    std::vector<double> mixed;
    for (uint32_t f = 0; f < data->face_count(); ++f) mixed.push_back(1 + (f * 7919 % 4));
    const uint32_t n = data->vertex_count();
    const std::vector<SurfacePoint> sources = {
        SurfacePoint::AtVertex(n / 3), SurfacePoint::OnEdge(data->faces[0], data->faces[1], 0.3),
        SurfacePoint::InFace(data->face_count() / 2, 0.2, 0.3, 0.5)};
    for (int variant = 0; variant < 4; ++variant) {
      WeightedOptions options;
      options.epsilon = 0.1;
      options.check_optimality = true;
      if (variant == 1) options.face_weight = mixed;
      if (variant == 2 && data == &grid) options.face_weight = RingWeights(grid, 5, 14);
      if (variant == 3) options.slope_cost = slope;
      absl::StatusOr<WeightedField> field = ComputeWeightedField(mesh, sources, options);
      ASSERT_TRUE(field.ok()) << "variant " << variant << ": " << field.status();
      EXPECT_GT(field->stats.nodes_settled, field->steiner_points / 2) << "variant " << variant;
    }
  }
}

// Many targets share one graph and one search: each path equals the one-target path bit for bit,
// an enclosed target is +inf with no points, and the search stops once every target is final.
TEST(WeightedFieldTest, PathsToManyTargetsShareOneSearch) {
  const MeshData data = JitteredGrid(20);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.epsilon = 0.1;
  options.face_weight = RingWeights(data, 14, 18);
  for (uint32_t f = 0; f < data.face_count(); ++f) {  // friction 3 on the right half
    if (FaceCentroid(data, f)[0] > 0.5) options.face_weight[f] *= 3;
  }
  const SurfacePoint from = SurfacePoint::InFace(7, 0.2, 0.3, 0.5);
  const std::vector<SurfacePoint> tos = {SurfacePoint::AtVertex(3 * 21 + 15),
                                         SurfacePoint::InFace(300, 0.6, 0.2, 0.2),
                                         SurfacePoint::AtVertex(16 * 21 + 16),  // enclosed
                                         SurfacePoint::AtVertex(12 * 21 + 2)};
  absl::StatusOr<std::vector<WeightedPath>> paths = ComputeWeightedPaths(mesh, from, tos, options);
  ASSERT_TRUE(paths.ok()) << paths.status();
  ASSERT_EQ(paths->size(), tos.size());
  for (size_t t = 0; t < tos.size(); ++t) {
    absl::StatusOr<WeightedPath> one = ComputeWeightedPath(mesh, from, tos[t], options);
    if (t == 2) {
      EXPECT_EQ(one.status().code(), absl::StatusCode::kNotFound);
      EXPECT_EQ((*paths)[t].cost, kInf);
      EXPECT_TRUE((*paths)[t].points.empty());
      continue;
    }
    ASSERT_TRUE(one.ok()) << one.status();
    EXPECT_EQ((*paths)[t].cost, one->cost) << t;
    ASSERT_EQ((*paths)[t].points.size(), one->points.size()) << t;
    for (size_t k = 0; k < one->points.size(); ++k) {
      EXPECT_EQ((*paths)[t].points[k].position, one->points[k].position) << t << " " << k;
    }
  }
}

TEST(WeightedFieldTest, BadOptionsAreNamed) {
  const TriangleMesh mesh = BuildMesh(MakeGrid(GridSpec{}));
  const std::vector<SurfacePoint> sources{SurfacePoint::AtVertex(0)};
  auto option_of = [&](const WeightedOptions& o) {
    absl::StatusOr<WeightedField> f = ComputeWeightedField(mesh, sources, o);
    EXPECT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument);
    return InvalidOptionOf(f.status());
  };
  for (const double eps : {0.0, -0.1, 1.0, std::nan("")}) {
    WeightedOptions o;
    o.epsilon = eps;
    EXPECT_EQ(option_of(o), "epsilon") << eps;
  }
  WeightedOptions o;
  o.max_distance = 0;
  EXPECT_EQ(option_of(o), "max_distance");
  for (const double w : {0.0, -1.0, std::nan("")}) {
    WeightedOptions bad;
    bad.face_weight.assign(mesh.face_count(), 1.0);
    bad.face_weight[7] = w;
    EXPECT_EQ(option_of(bad), "face_weight[7]") << w;
  }
  WeightedOptions short_list;
  short_list.face_weight.assign(mesh.face_count() - 1, 1.0);
  EXPECT_EQ(option_of(short_list), "face_weight");
  EXPECT_EQ(ComputeWeightedField(mesh, {}, WeightedOptions{}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(
      ComputeWeightedField(mesh, {SurfacePoint::AtVertex(1000)}, WeightedOptions{}).status().code(),
      absl::StatusCode::kInvalidArgument);
}

TEST(WeightedFieldTest, SteinerPointLimitAndCancel) {
  const TriangleMesh mesh = BuildMesh(MakeGrid(GridSpec{}));
  WeightedOptions o;
  o.epsilon = 0.1;
  absl::StatusOr<WeightedField> full = ComputeWeightedField(mesh, {SurfacePoint::AtVertex(0)}, o);
  ASSERT_TRUE(full.ok());
  o.max_steiner_points = full->steiner_points - 1;
  absl::StatusOr<WeightedField> limited =
      ComputeWeightedField(mesh, {SurfacePoint::AtVertex(0)}, o);
  EXPECT_EQ(limited.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(ExceededLimit(limited.status()), Limit::kSteinerPoints);
  o.max_steiner_points = full->steiner_points;
  EXPECT_TRUE(ComputeWeightedField(mesh, {SurfacePoint::AtVertex(0)}, o).ok());
  CancelToken cancel;
  cancel.Cancel();
  o.cancel = &cancel;
  EXPECT_EQ(ComputeWeightedField(mesh, {SurfacePoint::AtVertex(0)}, o).status().code(),
            absl::StatusCode::kCancelled);
}

TEST(WeightedFieldTest, MaxDistanceStopsTheSearch) {
  const MeshData data = MakeGrid(GridSpec{});
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions o;
  o.epsilon = 0.1;
  o.max_distance = 0.5;
  absl::StatusOr<WeightedField> f = ComputeWeightedField(mesh, {SurfacePoint::AtVertex(0)}, o);
  ASSERT_TRUE(f.ok());
  for (uint32_t v = 0; v < data.vertex_count(); ++v) {
    if (f->cost[v] < kInf) {
      EXPECT_LE(f->cost[v], 0.5);
    }
    const double d = Distance3(VertexPosition(data, 0), VertexPosition(data, v));
    if (d * (1 + o.epsilon) < 0.5) {
      EXPECT_LT(f->cost[v], kInf) << v;
    }
    if (d > 0.5) {
      EXPECT_EQ(f->cost[v], kInf) << v;
    }
  }
}

TEST(WeightedFieldTest, DeterministicBitForBit) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok());
  WeightedOptions o;
  o.epsilon = 0.1;
  for (uint32_t f = 0; f < mesh->face_count(); ++f) o.face_weight.push_back(1 + (f * 37 % 11));
  const std::vector<SurfacePoint> sources{
      SurfacePoint::AtVertex(0),
      SurfacePoint::OnEdge(mesh->FaceVertex(5, 0), mesh->FaceVertex(5, 1), 0.3)};
  absl::StatusOr<WeightedField> a = ComputeWeightedField(*mesh, sources, o);
  absl::StatusOr<WeightedField> b = ComputeWeightedField(*mesh, sources, o);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->cost, b->cost);
  EXPECT_EQ(a->source, b->source);
}

// A jittered grid of cells x cells squares on the unit square.
// Epsilon 0.1 with these weights, constant speed, then with a slope cost 1 on the level rising to
// 3 straight up or down.
std::vector<WeightedOptions> WithAndWithoutSlope(const std::vector<double>& weights) {
  WeightedOptions flat;
  flat.epsilon = 0.1;
  flat.face_weight = weights;
  WeightedOptions sloped = flat;
  auto slope = std::make_shared<SlopeCost>();
  for (int i = 0; i <= 32; ++i) slope->per_metre.push_back(1 + 2 * std::abs(-1 + i / 16.0));
  sloped.slope_cost = slope;
  return {flat, sloped};
}

// Costs at points stop the search once every point is final, with the whole search's answers bit
// for bit; one WeightedSurface serves many queries, from several threads at once, with each one's
// own answers, and built for the queries' sources it is the one-shot call's graph (bit for bit).
// Friction and a slope cost (asymmetric), two sources.
TEST(WeightedFieldTest, CostsAtPointsStopEarlyOnASharedSurface) {
  const MeshData data = JitteredGrid(30);
  const TriangleMesh mesh = BuildMesh(data);
  std::vector<double> weights;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    weights.push_back(FaceCentroid(data, f)[0] > 0.3 ? 2 : 1);
  }
  for (const WeightedOptions& options : WithAndWithoutSlope(weights)) {
    const int variant = options.slope_cost != nullptr;
    const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(31 * 5 + 5),
                                               SurfacePoint::InFace(40, 0.2, 0.3, 0.5)};
    absl::StatusOr<WeightedSurface> surface = WeightedSurface::Build(mesh, options, sources);
    ASSERT_TRUE(surface.ok()) << surface.status();
    // Near the sources, and one across the grid.
    const std::vector<std::vector<SurfacePoint>> queries = {
        {SurfacePoint::AtVertex(31 * 7 + 6), SurfacePoint::InFace(100, 0.6, 0.2, 0.2)},
        {SurfacePoint::AtVertex(31 * 29 + 29), SurfacePoint::AtVertex(31 * 6 + 4)}};
    std::vector<absl::StatusOr<WeightedCosts>> early(queries.size(), absl::UnknownError("not run"));
    {
      std::vector<std::thread> threads;
      for (size_t q = 0; q < queries.size(); ++q) {
        threads.emplace_back([&, q] { early[q] = surface->CostsAt(sources, queries[q]); });
      }
      for (std::thread& t : threads) t.join();
    }
    for (size_t q = 0; q < queries.size(); ++q) {
      absl::StatusOr<WeightedCosts> whole = surface->CostsAt(sources, queries[q], /*whole=*/true);
      absl::StatusOr<WeightedCosts> fresh =
          ComputeWeightedCostsAt(mesh, sources, queries[q], options);
      ASSERT_TRUE(early[q].ok() && whole.ok() && fresh.ok()) << early[q].status();
      EXPECT_EQ(early[q]->cost, whole->cost) << variant << " " << q;
      EXPECT_EQ(early[q]->source, whole->source) << variant << " " << q;
      EXPECT_EQ(fresh->cost, whole->cost) << variant << " " << q;
      for (const double c : whole->cost) EXPECT_TRUE(std::isfinite(c) && c > 0);
      if (q == 0) {  // near points: a small part of the graph
        EXPECT_LT(early[q]->stats.nodes_settled, whole->stats.nodes_settled / 4) << variant;
      }
    }
  }
}

// A path heads for its target (A*, cost + a lower bound of the cost left): it settles a part of
// the surface, and its cost is the whole field's at the target, bit for bit. Friction 1-3 with a
// slope cost too (no A*: the search stops once the target is final; its points are denser near
// the source, so that is more than half of them); the target a vertex half-way across.
TEST(WeightedFieldTest, PathsHeadForTheirTargets) {
  const MeshData data = JitteredGrid(30);
  const TriangleMesh mesh = BuildMesh(data);
  std::vector<double> weights;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    weights.push_back(1 + (FaceCentroid(data, f)[1] > 0.6) + (f * 7919 % 5 == 0));
  }
  for (const WeightedOptions& options : WithAndWithoutSlope(weights)) {
    const int variant = options.slope_cost != nullptr;
    const SurfacePoint from = SurfacePoint::AtVertex(31 * 15 + 2);
    const uint32_t to = 31 * 15 + 17;
    absl::StatusOr<WeightedPath> path =
        ComputeWeightedPath(mesh, from, SurfacePoint::AtVertex(to), options);
    absl::StatusOr<WeightedField> field = ComputeWeightedField(mesh, {from}, options);
    ASSERT_TRUE(path.ok() && field.ok()) << path.status();
    EXPECT_EQ(path->cost, field->cost[to]) << variant;
    EXPECT_LT(path->stats.nodes_settled, field->stats.nodes_settled / (variant ? 1.5 : 2))
        << variant;
  }
}

// The work budget (max_windows) bounds the graph's searches too, in links relaxed
// (kGraphLinksPerWindow a window): a field, a path and costs on a shared surface over it are
// refused naming Limit::kWindows, and one at its size answers as without a budget (bit for bit).
// Friction and a slope cost. Before the budget reached the graph it was ignored there.
TEST(WeightedFieldTest, WorkBudgetBoundsTheGraphsSearches) {
  const MeshData data = JitteredGrid(20);
  const TriangleMesh mesh = BuildMesh(data);
  std::vector<double> weights;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    weights.push_back(1 + 3 * (FaceCentroid(data, f)[0] > 0.4));
  }
  const SurfacePoint from = SurfacePoint::AtVertex(21 * 10 + 1);
  const SurfacePoint to = SurfacePoint::AtVertex(21 * 10 + 19);
  for (WeightedOptions options : WithAndWithoutSlope(weights)) {
    const int variant = options.slope_cost != nullptr;
    absl::StatusOr<WeightedField> full = ComputeWeightedField(mesh, {from}, options);
    absl::StatusOr<WeightedPath> path = ComputeWeightedPath(mesh, from, to, options);
    ASSERT_TRUE(full.ok() && path.ok()) << variant;
    const uint64_t links = full->stats.edge_relaxations;
    ASSERT_GT(links, 100 * kGraphLinksPerWindow) << variant;
    // A budget the whole search fits in: the same answers.
    options.max_windows = links / kGraphLinksPerWindow + 1;
    absl::StatusOr<WeightedField> within = ComputeWeightedField(mesh, {from}, options);
    ASSERT_TRUE(within.ok()) << within.status();
    EXPECT_EQ(within->cost, full->cost) << variant;
    // A tenth of it: refused, naming the budget.
    options.max_windows = links / kGraphLinksPerWindow / 10;
    absl::StatusOr<WeightedField> over = ComputeWeightedField(mesh, {from}, options);
    EXPECT_EQ(over.status().code(), absl::StatusCode::kResourceExhausted) << variant;
    EXPECT_EQ(ExceededLimit(over.status()), Limit::kWindows) << variant;
    EXPECT_NE(over.status().message().find("work budget exceeded"), absl::string_view::npos);
    options.max_windows = path->stats.edge_relaxations / kGraphLinksPerWindow / 10;
    absl::StatusOr<WeightedPath> over_path = ComputeWeightedPath(mesh, from, to, options);
    EXPECT_EQ(ExceededLimit(over_path.status()), Limit::kWindows) << variant;
    // On a surface shared between queries, the budget it was built under bounds each query.
    absl::StatusOr<WeightedSurface> surface = WeightedSurface::Build(mesh, options, {from}, {to});
    ASSERT_TRUE(surface.ok()) << surface.status();
    EXPECT_EQ(ExceededLimit(surface->CostsAt({from}, {to}, /*whole=*/true).status()),
              Limit::kWindows)
        << variant;
  }
}

}  // namespace
}  // namespace geodex
