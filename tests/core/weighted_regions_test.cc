// Travel costs by regions (weighted_regions.h): exact where every passable face weighs the same
// (against the exact engine, an analytic detour round a wall, a path through a vertex where two
// passable parts meet only there), and with several weights within the bound (Snell's law) and
// never above the bounded graph on the same boundary points.

#include "weighted_regions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/limits.h"
#include "geodex/shortest_path.h"
#include "geodex/travel_cost.h"
#include "geodex/weighted_field.h"
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

absl::StatusOr<WeightedCosts> CostsAt(const TriangleMesh& mesh, const WeightedOptions& options,
                                      const std::vector<SurfacePoint>& sources,
                                      const std::vector<SurfacePoint>& targets) {
  std::vector<SurfacePoint> anchors = sources;
  anchors.insert(anchors.end(), targets.begin(), targets.end());
  absl::StatusOr<std::shared_ptr<const RegionSurface>> regions =
      RegionSurface::Build(mesh, options, anchors);
  if (!regions.ok()) return regions.status();
  return (*regions)->CostsAt(sources, targets, false, {});
}

// A 2 m x 1 m plane of cells_x x cells_y cells, diagonals alternating (vertex (i, j) =
// (cells_x + 1) j + i): two weights meet along x = 1.
MeshData TwoByOnePlane(uint32_t cells_x, uint32_t cells_y) {
  GridSpec spec;
  spec.cells_x = cells_x;
  spec.cells_y = cells_y;
  spec.width = 2;
  spec.height = 1;
  spec.alternate_diagonals = true;
  return MakeGrid(spec);
}

// The least cost from `a` (x < 1, weight `west`) to `b` (x > 1, weight `east`) on that plane:
// straight to the crossing on x = 1 that Snell's law picks, straight on from there.
double RefractedAtXOne(const Vec3& a, const Vec3& b, double west, double east) {
  auto cost = [&](double y) {
    return west * std::hypot(1 - a[0], y - a[1]) + east * std::hypot(b[0] - 1, b[1] - y);
  };
  return cost(GoldenSectionArgMin(cost, 0, 1));
}

// A 2 x 2 grid of unit cells, vertex (i, j) = 3 j + i.
MeshData TwoByTwoGrid() {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 2;
  spec.width = spec.height = 2;
  return MakeGrid(spec);
}

// Weight w on cells (0, 0) and (1, 1), which meet only at the vertex (1, 1); the rest impassable.
std::vector<double> DiagonalCellsPassable(const MeshData& grid, double w) {
  std::vector<double> weights;
  for (uint32_t f = 0; f < grid.face_count(); ++f) {
    const Vec3 c = FaceCentroid(grid, f);
    weights.push_back((c[0] < 1) == (c[1] < 1) ? w : kInf);
  }
  return weights;
}

TEST(WeightedRegionsTest, WhoServes) {
  WeightedOptions options;
  EXPECT_TRUE(RegionsServe(options));
  options.face_weight = {2, kInf, 2, 2};
  EXPECT_TRUE(RegionsServe(options));
  options.face_weight = {2, kInf, 1, 2};
  EXPECT_FALSE(RegionsServe(options));
  options.face_weight = {kInf, kInf};
  EXPECT_TRUE(RegionsServe(options));
  options.face_weight.clear();
  options.slope_cost = std::make_shared<SlopeCost>(SlopeCost{{1, 1}});
  EXPECT_FALSE(RegionsServe(options));
}

// One friction everywhere, through the public query: the exact field x the friction / the speed.
TEST(WeightedRegionsTest, OneWeightIsTheExactFieldScaled) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<SurfacePoint> sources{SurfacePoint::AtVertex(7),
                                          SurfacePoint::InFace(100, 0.2, 0.3, 0.5)};
  absl::StatusOr<DistanceField> exact = ComputeDistanceField(*mesh, sources);
  ASSERT_TRUE(exact.ok()) << exact.status();
  GeodesicOptions options;
  TravelCost travel;
  travel.speed_kmh = 3.6;  // 1 m/s
  travel.face_weight = std::make_shared<std::vector<double>>(mesh->face_count(), 2.5);
  options.travel = travel;
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sources, options);
  ASSERT_TRUE(field.ok()) << field.status();
  ASSERT_EQ(field->distance.size(), exact->distance.size());
  for (size_t v = 0; v < field->distance.size(); ++v) {
    EXPECT_NEAR(field->distance[v], 2.5 * exact->distance[v], 1e-12 * (1 + exact->distance[v]))
        << "vertex " << v;
    EXPECT_EQ(field->source[v], exact->source[v]) << "vertex " << v;
  }
}

// A wall with a gap, impassable: the way round it, exactly.
TEST(WeightedRegionsTest, ImpassableWallIsGoneAroundExactly) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 20;
  const MeshData data = MakeGrid(spec);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    const Vec3 c = FaceCentroid(data, f);
    const bool wall = c[0] > 0.45 && c[0] < 0.55 && c[1] < 0.8;
    options.face_weight.push_back(wall ? kInf : 1.0);
  }
  ASSERT_TRUE(RegionsServe(options));
  const uint32_t s = 4 * 21 + 4, t = 4 * 21 + 16;  // (0.2, 0.2) and (0.8, 0.2)
  const double detour = 2 * 0.65 + 0.1;            // via (0.45, 0.8) and (0.55, 0.8)
  absl::StatusOr<WeightedCosts> costs =
      CostsAt(mesh, options, {SurfacePoint::AtVertex(s)}, {SurfacePoint::AtVertex(t)});
  ASSERT_TRUE(costs.ok()) << costs.status();
  EXPECT_NEAR(costs->cost[0], detour, 1e-12);
  EXPECT_EQ(costs->steiner_points, 0u);
}

// Two passable cells that meet only at a vertex (every other face impassable): paths pass
// through it, as the graph's do, though the passable faces split there.
TEST(WeightedRegionsTest, PathsPassWherePassableFacesMeetAtAVertex) {
  const MeshData data = TwoByTwoGrid();
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.face_weight = DiagonalCellsPassable(data, 3.0);
  // (1, 0) to (2, 1) and to the far corner (2, 2), through the vertex (1, 1).
  const std::vector<SurfacePoint> targets{SurfacePoint::AtVertex(5), SurfacePoint::AtVertex(8),
                                          SurfacePoint::AtVertex(2)};
  absl::StatusOr<WeightedCosts> costs =
      CostsAt(mesh, options, {SurfacePoint::AtVertex(1)}, targets);
  ASSERT_TRUE(costs.ok()) << costs.status();
  EXPECT_NEAR(costs->cost[0], 3 * 2, 1e-12);
  EXPECT_NEAR(costs->cost[1], 3 * (1 + std::sqrt(2.0)), 1e-12);
  EXPECT_EQ(costs->cost[2], kInf);  // (2, 0): impassable all round
  // The path passes through (1, 1), named on the surface, and costs what it says.
  absl::StatusOr<std::shared_ptr<const RegionSurface>> surface =
      RegionSurface::Build(mesh, options);
  ASSERT_TRUE(surface.ok()) << surface.status();
  absl::StatusOr<std::vector<WeightedPath>> paths =
      (*surface)->Paths(SurfacePoint::AtVertex(1), {targets[1], targets[2]}, {});
  ASSERT_TRUE(paths.ok()) << paths.status();
  const WeightedPath& path = (*paths)[0];
  EXPECT_NEAR(path.cost, costs->cost[1], 1e-12);
  ASSERT_GE(path.points.size(), 3u);
  EXPECT_EQ(path.points.front().where.vertex, 1u);
  EXPECT_EQ(path.points.back().where.vertex, 8u);
  int at_junction = 0;
  double cost = 0;
  for (size_t k = 0; k < path.points.size(); ++k) {
    const PathPoint& p = path.points[k];
    if (p.where.kind == SurfacePoint::Kind::kVertex && p.where.vertex == 4) {
      ++at_junction;
      EXPECT_EQ(p.position, (std::array<double, 3>{1, 1, 0}));
    }
    if (k > 0) cost += 3 * Distance3(path.points[k - 1].position, p.position);
  }
  EXPECT_EQ(at_junction, 1);  // once: the copies' repeat is dropped
  EXPECT_NEAR(cost, path.cost, 1e-12);
  EXPECT_EQ((*paths)[1].cost, kInf);
  EXPECT_TRUE((*paths)[1].points.empty());
  // The graph agrees within its bound.
  absl::StatusOr<WeightedCosts> graph =
      ComputeWeightedCostsAt(mesh, {SurfacePoint::AtVertex(1)}, targets, options);
  ASSERT_TRUE(graph.ok()) << graph.status();
  EXPECT_LE(graph->cost[0], costs->cost[0] * (1 + options.epsilon));
  EXPECT_GE(graph->cost[0], costs->cost[0] * (1 - 1e-12));
  // Every face impassable: nothing is reached, and the points are still checked.
  options.face_weight.assign(data.face_count(), kInf);
  absl::StatusOr<WeightedCosts> none =
      CostsAt(mesh, options, {SurfacePoint::AtVertex(1)}, {SurfacePoint::AtVertex(5)});
  ASSERT_TRUE(none.ok()) << none.status();
  EXPECT_EQ(none->cost[0], kInf);
  EXPECT_FALSE(CostsAt(mesh, options, {SurfacePoint::AtVertex(99)}, {}).ok());
}

// A source vertex whose faces are all impassable (a summit under --max-slope) stands where it is:
// cost 0 there, as on the graph, and nothing else is reached from it.
TEST(WeightedRegionsTest, StrandedSourceVertexCostsNothingAtItself) {
  const MeshData data = TwoByTwoGrid();
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.face_weight = DiagonalCellsPassable(data, 1.0);
  const std::vector<SurfacePoint> sources{SurfacePoint::AtVertex(1), SurfacePoint::AtVertex(2)};
  absl::StatusOr<std::shared_ptr<const RegionSurface>> surface =
      RegionSurface::Build(mesh, options, sources);
  ASSERT_TRUE(surface.ok()) << surface.status();
  absl::StatusOr<WeightedField> field = (*surface)->Field(sources, {});
  absl::StatusOr<WeightedField> graph = ComputeWeightedField(mesh, sources, options);
  ASSERT_TRUE(field.ok()) << field.status();
  ASSERT_TRUE(graph.ok()) << graph.status();
  EXPECT_EQ(field->cost[2], 0);  // (2, 0): impassable all round, a source itself
  EXPECT_EQ(field->source[2], 1u);
  EXPECT_EQ(graph->cost[2], 0);
  EXPECT_EQ(graph->source[2], 1u);
  EXPECT_EQ(field->cost[1], 0);
  EXPECT_EQ(field->source[1], 0u);
  EXPECT_EQ(field->cost[6], kInf);  // (0, 2): impassable all round, not a source
  // At points: the stranded source's vertex is 0, the rest only from the other source.
  absl::StatusOr<WeightedCosts> costs = (*surface)->CostsAt(
      {SurfacePoint::AtVertex(2)},
      {SurfacePoint::AtVertex(2), SurfacePoint::OnEdge(2, 1, 1.0), SurfacePoint::AtVertex(4)},
      false, {});
  ASSERT_TRUE(costs.ok()) << costs.status();
  EXPECT_EQ(costs->cost, (std::vector<double>{0, kInf, kInf}));
  EXPECT_EQ(costs->source[0], 0u);
  // A path from it to itself: no way to go, nothing to walk.
  absl::StatusOr<std::vector<WeightedPath>> paths =
      (*surface)->Paths(SurfacePoint::AtVertex(2), {SurfacePoint::AtVertex(2)}, {});
  ASSERT_TRUE(paths.ok()) << paths.status();
  EXPECT_EQ((*paths)[0].cost, 0);
  ASSERT_FALSE((*paths)[0].points.empty());
  EXPECT_EQ((*paths)[0].points.front().position, (std::array<double, 3>{2, 0, 0}));
}

// A point in a zero-area face (or on its edge) lies on an edge beside it with area: taken there
// (the exact engine places nothing inside such a face); errors name the surface's own vertices.
TEST(WeightedRegionsTest, PointsInZeroAreaFacesAndMissingEdges) {
  MeshData data;
  data.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0, 0};
  data.faces = {0, 4, 3, 4, 1, 2, 4, 2, 3, 0, 1, 4};  // the last: (0, 0) - (1, 0) - (0.5, 0)
  const TriangleMesh mesh = BuildMesh(data);
  ASSERT_TRUE(mesh.FaceDegenerate(3));
  WeightedOptions options;
  options.face_weight.assign(4, 2.0);
  const SurfacePoint in_sliver = SurfacePoint::InFace(3, 0.25, 0.75, 0);  // (0.75, 0)
  absl::StatusOr<WeightedCosts> costs =
      CostsAt(mesh, options, {SurfacePoint::AtVertex(3)}, {in_sliver, SurfacePoint::AtVertex(2)});
  ASSERT_TRUE(costs.ok()) << costs.status();
  EXPECT_NEAR(costs->cost[0], 2 * 1.25, 1e-12);  // (0, 1) to (0.75, 0), straight
  EXPECT_NEAR(costs->cost[1], 2 * 1.0, 1e-12);
  costs = CostsAt(mesh, options, {in_sliver}, {SurfacePoint::AtVertex(2)});
  ASSERT_TRUE(costs.ok()) << costs.status();
  EXPECT_NEAR(costs->cost[0], 2 * std::hypot(0.25, 1.0), 1e-12);
  // On the edge of the zero-area face only: the same position on the edge beside it.
  costs = CostsAt(mesh, options, {SurfacePoint::AtVertex(3)}, {SurfacePoint::OnEdge(0, 1, 0.3)});
  ASSERT_TRUE(costs.ok()) << costs.status();
  EXPECT_NEAR(costs->cost[0], 2 * std::hypot(0.3, 1.0), 1e-12);
  // An edge the mesh does not have.
  absl::StatusOr<std::shared_ptr<const RegionSurface>> surface =
      RegionSurface::Build(mesh, options);
  ASSERT_TRUE(surface.ok()) << surface.status();
  absl::StatusOr<WeightedCosts> bad =
      (*surface)->CostsAt({SurfacePoint::AtVertex(3)}, {SurfacePoint::OnEdge(0, 2, 0.5)}, true, {});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("no edge between vertices 0 and 2"), std::string::npos)
      << bad.status();
}

// geodexd's window budget (--max_windows) bounds one-weight travel solves as it bounds fields.
TEST(WeightedRegionsTest, WindowBudgetBoundsOneWeightSolves) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  GeodesicOptions options;
  TravelCost travel;
  travel.speed_kmh = 3.6;
  travel.face_weight = std::make_shared<std::vector<double>>(mesh->face_count(), 2.0);
  options.travel = travel;
  options.max_windows = 100;
  absl::StatusOr<DistanceField> field =
      ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, options);
  EXPECT_EQ(field.status().code(), absl::StatusCode::kResourceExhausted) << field.status();
  EXPECT_EQ(ExceededLimit(field.status()), Limit::kWindows);
  options.max_windows = 0;
  field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, options);
  EXPECT_TRUE(field.ok()) << field.status();
}

// What a polyline on a plane (z = 0) costs as drawn: each segment's length times the least weight
// of the faces holding its midpoint (one face across its inside, the lighter of two along an
// edge: a segment of the engine's never leaves its region); +inf for a midpoint off the surface.
double CostAlong(const MeshData& data, const std::vector<double>& weight,
                 const std::vector<PathPoint>& points) {
  double total = 0;
  for (size_t k = 1; k < points.size(); ++k) {
    const auto& p = points[k - 1].position;
    const auto& q = points[k].position;
    const double length = std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    if (!(length > 0)) continue;
    const double mx = (p[0] + q[0]) / 2, my = (p[1] + q[1]) / 2;
    double w = kInf;
    for (uint32_t f = 0; f < data.face_count(); ++f) {
      const Vec3 a = VertexPosition(data, data.faces[3 * f]);
      const Vec3 b = VertexPosition(data, data.faces[3 * f + 1]);
      const Vec3 c = VertexPosition(data, data.faces[3 * f + 2]);
      auto side = [&](const Vec3& u, const Vec3& v) {
        return (v[0] - u[0]) * (my - u[1]) - (v[1] - u[1]) * (mx - u[0]);
      };
      const double s0 = side(a, b), s1 = side(b, c), s2 = side(c, a);
      const double tol = 1e-12;
      const bool in =
          (s0 >= -tol && s1 >= -tol && s2 >= -tol) || (s0 <= tol && s1 <= tol && s2 <= tol);
      if (in) w = std::min(w, weight[f]);
    }
    total += w * length;
  }
  return total;
}

// Several weights: a path is traced back through the regions' boundary points (issue 55), so its
// cost is the field's at its end, bit for bit, and the polyline costs what it says as drawn (to
// 1e-9): straight in each face, refracted on the boundaries, never jumping. Snell's half-plane
// (every target within the bound of the refracted optimum, never below), and a jittered grid with
// three weights in oblique bands, where paths run along the boundary chains too. Before, the
// regions refused paths across their boundaries and the graph answered them (another engine:
// 5210.1518 s against the field's 5210.1179 s in issue 55's case).
TEST(WeightedRegionsTest, PathsAcrossRegionBoundariesAreTheFieldsOwn) {
  struct Case {
    MeshData data;
    std::vector<double> weight;
    uint32_t from;
    bool snell;
  };
  std::vector<Case> cases;
  {
    Case c{TwoByOnePlane(10, 5), {}, 1 * 11 + 1, true};
    for (uint32_t f = 0; f < c.data.face_count(); ++f) {
      c.weight.push_back(FaceCentroid(c.data, f)[0] > 1 ? 4.0 : 1.0);
    }
    cases.push_back(std::move(c));
  }
  {
    GridSpec spec;
    spec.cells_x = spec.cells_y = 12;
    spec.jitter = 0.2;
    Case c{MakeGrid(spec), {}, 13 * 2 + 2, false};
    for (uint32_t f = 0; f < c.data.face_count(); ++f) {
      const Vec3 m = FaceCentroid(c.data, f);
      const double band = m[0] + 0.6 * m[1];
      c.weight.push_back(band < 0.5 ? 1.0 : band < 0.9 ? 3.0 : 1.5);
    }
    cases.push_back(std::move(c));
  }
  for (size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    const TriangleMesh mesh = BuildMesh(c.data);
    WeightedOptions options;
    options.epsilon = 0.05;
    options.face_weight = c.weight;
    const SurfacePoint from = SurfacePoint::AtVertex(c.from);
    std::vector<SurfacePoint> tos;
    for (uint32_t v = 0; v < c.data.vertex_count(); v += 7)
      tos.push_back(SurfacePoint::AtVertex(v));
    absl::StatusOr<std::shared_ptr<const RegionSurface>> regions =
        RegionSurface::Build(mesh, options, {from});
    ASSERT_TRUE(regions.ok()) << regions.status();
    ASSERT_GT((*regions)->boundary_points(), 0u);
    absl::StatusOr<WeightedField> field = (*regions)->Field({from}, {});
    absl::StatusOr<std::vector<WeightedPath>> paths = (*regions)->Paths(from, tos, {});
    ASSERT_TRUE(field.ok() && paths.ok()) << paths.status();
    size_t crossing = 0;
    for (size_t t = 0; t < tos.size(); ++t) {
      const WeightedPath& path = (*paths)[t];
      const uint32_t to = tos[t].vertex;
      EXPECT_EQ(path.cost, field->cost[to]) << k << " to " << to;
      if (to == c.from) continue;
      ASSERT_GE(path.points.size(), 2u) << k << " to " << to;
      EXPECT_EQ(path.points.front().where.vertex, c.from);
      EXPECT_EQ(path.points.back().where.vertex, to);
      EXPECT_NEAR(CostAlong(c.data, c.weight, path.points), path.cost, 1e-9 * path.cost)
          << k << " to " << to;
      const Vec3 a = VertexPosition(c.data, c.from), b = VertexPosition(c.data, to);
      const double straight = std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
      crossing += path.cost > 1.01 * straight;  // a path that crossed into a heavier region
      if (c.snell && b[0] > 1 + 1e-9) {
        const double best = RefractedAtXOne(a, b, 1, 4);
        EXPECT_GE(path.cost, best * (1 - 1e-12)) << to;
        EXPECT_LE(path.cost, best * (1 + options.epsilon)) << to;
      }
    }
    EXPECT_GT(crossing, 3u) << k;
  }
  // Through the public query: a travel path with several weights is the travel field's time at
  // its end (the regions answer both).
  const Case& c = cases[1];
  const TriangleMesh mesh = BuildMesh(c.data);
  TravelCost travel;
  travel.speed_kmh = 3.6;
  travel.epsilon = 0.05;
  travel.face_weight = std::make_shared<const std::vector<double>>(c.weight);
  GeodesicOptions options;
  options.travel = travel;
  const SurfacePoint from = SurfacePoint::AtVertex(c.from);
  const uint32_t to = c.data.vertex_count() - 3;
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, {from}, options);
  PathQueryOptions query;
  query.solver = options;
  absl::StatusOr<PathQueryResult> path =
      ComputeShortestPath(mesh, from, SurfacePoint::AtVertex(to), query);
  ASSERT_TRUE(field.ok() && path.ok()) << path.status();
  EXPECT_EQ(path->distance, field->distance[to]);
}

// Several weights: friction 4 beyond x = 1. Every vertex there against its refracted optimum
// (Snell's law), within the bound and never below.
TEST(WeightedRegionsTest, SnellsLawAcrossAFrictionFourHalfPlane) {
  const MeshData data = TwoByOnePlane(10, 5);
  const TriangleMesh mesh = BuildMesh(data);
  for (const double eps : {0.1, 0.01}) {
    WeightedOptions options;
    options.epsilon = eps;
    for (uint32_t f = 0; f < data.face_count(); ++f) {
      options.face_weight.push_back(FaceCentroid(data, f)[0] > 1 ? 4.0 : 1.0);
    }
    const uint32_t s = 1 * 11 + 1;
    std::vector<SurfacePoint> targets;
    std::vector<double> best;
    for (uint32_t v = 0; v < data.vertex_count(); ++v) {
      const Vec3 ps = VertexPosition(data, s), pt = VertexPosition(data, v);
      if (pt[0] < 1 + 1e-9) continue;
      targets.push_back(SurfacePoint::AtVertex(v));
      best.push_back(RefractedAtXOne(ps, pt, 1, 4));
    }
    absl::StatusOr<WeightedCosts> costs =
        CostsAt(mesh, options, {SurfacePoint::AtVertex(s)}, targets);
    ASSERT_TRUE(costs.ok()) << costs.status();
    EXPECT_GT(costs->steiner_points, 0u);
    double worst = 0;
    for (size_t t = 0; t < targets.size(); ++t) {
      EXPECT_GE(costs->cost[t], best[t] * (1 - 1e-12)) << "target " << t;
      EXPECT_LE(costs->cost[t], best[t] * (1 + eps)) << "target " << t;
      worst = std::max(worst, costs->cost[t] / best[t] - 1);
    }
    std::printf("Snell eps %g: %llu boundary points, worst 1 + %.3g\n", eps,
                static_cast<unsigned long long>(costs->steiner_points), worst);
  }
}

// A boundary point whose neighbour on the edge, plus the way along it, is no dearer covers
// nothing its neighbour does not, so it emits nothing into that side (docs/engine.md). Out of a
// friction-10 half-plane into a friction-1 half only the points near the foot of the source's
// perpendicular emit: 0.32x the windows of the mirror image (friction 1 into 10, where every
// point emits), against 0.51x without the rule (from the heavy side every point's windows enter
// the light half), with the same boundary points and geometry, and answers within the bound. A
// point priced along the chain is covered exactly, not just within a rounding.
TEST(WeightedRegionsTest, CoveredBoundaryPointsEmitNothing) {
  const MeshData data = TwoByOnePlane(20, 10);
  const TriangleMesh mesh = BuildMesh(data);
  auto windows = [&](double west, double east) -> uint64_t {
    WeightedOptions options;
    options.epsilon = 0.05;
    for (uint32_t f = 0; f < data.face_count(); ++f) {
      options.face_weight.push_back(FaceCentroid(data, f)[0] > 1 ? east : west);
    }
    const std::vector<SurfacePoint> sources{SurfacePoint::AtVertex(5 * 21 + 1)};  // (0.1, 0.5)
    absl::StatusOr<std::shared_ptr<const RegionSurface>> regions =
        RegionSurface::Build(mesh, options, sources);
    EXPECT_TRUE(regions.ok()) << regions.status();
    if (!regions.ok()) return 0;
    absl::StatusOr<WeightedField> field = (*regions)->Field(sources, {});
    EXPECT_TRUE(field.ok()) << field.status();
    if (!field.ok()) return 0;
    // The far corner, against the refracted optimum (Snell's law through the boundary x = 1).
    const double best = RefractedAtXOne(VertexPosition(data, sources[0].vertex),
                                        VertexPosition(data, 20), west, east);
    EXPECT_GE(field->cost[20], best * (1 - 1e-12));
    EXPECT_LE(field->cost[20], best * (1 + options.epsilon));
    return field->stats.edge_relaxations;
  };
  const uint64_t heavy_to_light = windows(10, 1), light_to_heavy = windows(1, 10);
  std::printf("windows: friction 10 into 1: %llu, 1 into 10: %llu\n",
              static_cast<unsigned long long>(heavy_to_light),
              static_cast<unsigned long long>(light_to_heavy));
  EXPECT_GT(heavy_to_light, 0u);
  EXPECT_LT(heavy_to_light, light_to_heavy * 2 / 5);
}

// Several weights on a real mesh (bands of 1 to 4 by height): never above the bounded graph's
// cost (the same boundary points, exact inside regions) and never below its lower bound; a
// travel field with those weights is the regions'.
TEST(WeightedRegionsTest, SeveralWeightsAgainstTheBoundedGraph) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<SurfacePoint> sources{SurfacePoint::AtVertex(7)};
  WeightedOptions options;
  options.epsilon = 0.1;
  for (uint32_t f = 0; f < mesh->face_count(); ++f) {
    double y = 0;
    for (int k = 0; k < 3; ++k) y += mesh->Position(mesh->FaceVertex(f, k))[1] / 3;
    options.face_weight.push_back(1 + std::fmod(std::abs(std::floor(y * 7)), 4));
  }
  ASSERT_FALSE(RegionsServe(options));
  absl::StatusOr<WeightedField> graph = ComputeWeightedField(*mesh, sources, options);
  ASSERT_TRUE(graph.ok()) << graph.status();
  absl::StatusOr<std::shared_ptr<const RegionSurface>> surface =
      RegionSurface::Build(*mesh, options, sources);
  ASSERT_TRUE(surface.ok()) << surface.status();
  absl::StatusOr<WeightedField> regions = (*surface)->Field(sources, {});
  ASSERT_TRUE(regions.ok()) << regions.status();
  double below = 0;
  uint32_t most_below = 0;
  for (size_t v = 0; v < graph->cost.size(); ++v) {
    const double g = graph->cost[v], r = regions->cost[v];
    if (g == 0) {
      EXPECT_EQ(r, 0);
      continue;
    }
    EXPECT_GE(r, g / (1 + options.epsilon) * (1 - 1e-12)) << "vertex " << v;
    EXPECT_LE(r, g * (1 + 1e-12)) << "vertex " << v;
    if (1 - r / g > below) {
      below = 1 - r / g;
      most_below = static_cast<uint32_t>(v);
    }
  }
  std::printf("knight: %llu boundary points (graph %llu); regions below the graph by up to %.3g\n",
              static_cast<unsigned long long>(regions->steiner_points),
              static_cast<unsigned long long>(graph->steiner_points), below);
  EXPECT_GT(below, 1e-9);  // the regions gain somewhere, so the field below cannot be the graph's

  // The product: a travel field with these weights is the regions' (RegionsServeFields; at
  // 3.6 km/h a second is a unit of cost).
  ASSERT_TRUE(RegionsServeFields(options));
  TravelCost travel;
  travel.speed_kmh = 3.6;
  travel.epsilon = options.epsilon;
  travel.face_weight = std::make_shared<std::vector<double>>(options.face_weight);
  GeodesicOptions travel_options;
  travel_options.travel = travel;
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sources, travel_options);
  ASSERT_TRUE(field.ok()) << field.status();
  ASSERT_EQ(field->distance.size(), regions->cost.size());
  for (size_t v = 0; v < regions->cost.size(); ++v) {
    EXPECT_NEAR(field->distance[v], regions->cost[v], 1e-12 * (1 + regions->cost[v]))
        << "vertex " << v;
  }

  // Times at points and matrices too (SharesTravelSurface is false): at the vertex where the
  // regions gain most on the graph, and two others, they are the regions' field, not the graph's.
  EXPECT_FALSE(SharesTravelSurface(travel));
  const std::vector<uint32_t> at = {most_below, 0, static_cast<uint32_t>(mesh->vertex_count() / 2)};
  std::vector<SurfacePoint> targets;
  for (const uint32_t v : at) targets.push_back(SurfacePoint::AtVertex(v));
  absl::StatusOr<PointValues> values =
      ComputePointValues(*mesh, PointQuery{sources, targets, travel_options, false});
  ASSERT_TRUE(values.ok()) << values.status();
  absl::StatusOr<DistanceMatrix> matrix =
      ComputeDistanceMatrix(*mesh, sources, targets, travel_options);
  ASSERT_TRUE(matrix.ok()) << matrix.status();
  for (size_t t = 0; t < at.size(); ++t) {
    const double want = regions->cost[at[t]];
    EXPECT_NEAR(values->distance[t], want, 1e-12 * (1 + want)) << "vertex " << at[t];
    EXPECT_NEAR(matrix->values[t], want, 1e-12 * (1 + want)) << "vertex " << at[t];
  }
  EXPECT_LT(values->distance[0], graph->cost[most_below] * (1 - 1e-9));
}

}  // namespace
}  // namespace geodex
