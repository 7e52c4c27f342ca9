// Travel costs by regions (weighted_regions.h): exact where every passable face weighs the same
// (against the exact engine, an analytic detour round a wall, a path through a vertex where two
// passable parts meet only there), and with several weights within the bound (Snell's law) and
// never above the bounded graph on the same boundary points.

#include "weighted_regions.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/limits.h"
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

// Several weights: paths are the graph's (windows from a boundary point record no vertex to
// trace back through); the regions refuse rather than stop short.
TEST(WeightedRegionsTest, PathsRefusedAcrossRegionBoundaries) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 4;
  const MeshData data = MakeGrid(spec);
  const TriangleMesh mesh = BuildMesh(data);
  WeightedOptions options;
  options.epsilon = 0.1;
  for (uint32_t f = 0; f < data.face_count(); ++f) {
    options.face_weight.push_back(FaceCentroid(data, f)[0] < 0.5 ? 1.0 : 4.0);
  }
  absl::StatusOr<std::shared_ptr<const RegionSurface>> surface =
      RegionSurface::Build(mesh, options);
  ASSERT_TRUE(surface.ok()) << surface.status();
  ASSERT_GT((*surface)->boundary_points(), 0u);
  absl::StatusOr<std::vector<WeightedPath>> paths =
      (*surface)->Paths(SurfacePoint::AtVertex(0), {SurfacePoint::AtVertex(24)}, {});
  EXPECT_EQ(paths.status().code(), absl::StatusCode::kFailedPrecondition) << paths.status();
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

  // Times at points and matrices too (CostsUseSharedGraph is false): at the vertex where the
  // regions gain most on the graph, and two others, they are the regions' field, not the graph's.
  EXPECT_FALSE(CostsUseSharedGraph(travel));
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
