// Travel time through the public queries (geodex/travel_cost.h): a GeodesicOptions with a travel
// cost makes fields, point values, paths, matrices and isolines speak seconds from the weighted
// engine, within its bound; friction scales times; --max-slope blocks steep faces; what a travel
// cost cannot do is a named error.

#include "geodex/travel_cost.h"

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geometry_queries.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/weighted_field.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"

namespace geodex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TriangleMesh BuildMesh(const MeshData& data) {
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return *std::move(mesh);
}

// A square plane of cells x cells cells, `size` metres a side, its vertices jittered by `jitter`
// of a cell (0: a regular grid).
TriangleMesh SquarePlane(int cells, double size, double jitter = 0) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = cells;
  spec.width = spec.height = size;
  spec.jitter = jitter;
  return BuildMesh(MakeGrid(spec));
}

GeodesicOptions Travel(double speed_kmh, double epsilon = 0.05) {
  GeodesicOptions options;
  options.travel = TravelCost{};
  options.travel->speed_kmh = speed_kmh;
  options.travel->epsilon = epsilon;
  return options;
}

// A 10 m x 10 m plane: at 3.6 km/h (1 m/s) every time is the exact distance within the bound,
// and at 7.2 km/h half of it; the field says it is a travel field and its bound.
TEST(TravelCostTest, APlaneAtOneMetrePerSecondGivesDistancesInSeconds) {
  const TriangleMesh mesh = SquarePlane(8, 10, 0.2);
  const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(0)};
  absl::StatusOr<DistanceField> exact = ComputeDistanceField(mesh, sources);
  ASSERT_TRUE(exact.ok()) << exact.status();
  for (double speed : {3.6, 7.2}) {
    absl::StatusOr<DistanceField> time = ComputeDistanceField(mesh, sources, Travel(speed));
    ASSERT_TRUE(time.ok()) << time.status();
    EXPECT_EQ(time->travel_epsilon, 0.05);
    const double scale = 3.6 / speed;
    for (size_t v = 0; v < exact->distance.size(); ++v) {
      const double d = exact->distance[v] * scale;
      EXPECT_GE(time->distance[v], d * (1 - 1e-12)) << v;
      EXPECT_LE(time->distance[v], d * 1.05 + 1e-12) << v;
      EXPECT_EQ(time->source[v], 0u);
    }
  }
}

// Friction 2 everywhere doubles every time, bit for bit, in the field, at points and in paths.
// One weight: every answer is exact (weighted_regions.h), the exact engine's / the speed.
TEST(TravelCostTest, FrictionTwoDoublesEveryTime) {
  const TriangleMesh mesh = SquarePlane(6, 100, 0.25);
  const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(3)};
  GeodesicOptions plain = Travel(5), doubled = Travel(5);
  doubled.travel->face_weight = std::make_shared<std::vector<double>>(mesh.face_count(), 2.0);
  absl::StatusOr<DistanceField> a = ComputeDistanceField(mesh, sources, plain);
  absl::StatusOr<DistanceField> b = ComputeDistanceField(mesh, sources, doubled);
  ASSERT_TRUE(a.ok() && b.ok()) << a.status() << b.status();
  for (size_t v = 0; v < a->distance.size(); ++v) EXPECT_EQ(b->distance[v], 2 * a->distance[v]);
  const SurfacePoint to = SurfacePoint::InFace(20, 0.2, 0.3, 0.5);
  absl::StatusOr<PathQueryResult> pa = ComputeShortestPath(mesh, {sources[0], to, {plain}});
  absl::StatusOr<PathQueryResult> pb = ComputeShortestPath(mesh, {sources[0], to, {doubled}});
  ASSERT_TRUE(pa.ok() && pb.ok()) << pa.status() << pb.status();
  EXPECT_EQ(pb->distance, 2 * pa->distance);
  // The path's length is metres along it; at 5 km/h its time is length / (5 / 3.6).
  EXPECT_NEAR(pa->distance, pa->path.length * 3.6 / 5, 1e-9 * pa->distance);
  absl::StatusOr<PointValues> at = ComputePointValues(mesh, {sources, {to}, doubled});
  ASSERT_TRUE(at.ok()) << at.status();
  EXPECT_NEAR(at->distance[0], pb->distance, 1e-12 * pb->distance);
  absl::StatusOr<PathQueryResult> exact = ComputeShortestPath(mesh, {sources[0], to, {}});
  ASSERT_TRUE(exact.ok()) << exact.status();
  EXPECT_NEAR(pa->distance, exact->distance * 3.6 / 5, 1e-12 * pa->distance);
  EXPECT_NEAR(pa->path.length, exact->path.length, 1e-9 * exact->path.length);
  absl::StatusOr<PointValues> at_plain = ComputePointValues(mesh, {sources, {to}, plain});
  ASSERT_TRUE(at_plain.ok()) << at_plain.status();
  EXPECT_EQ(at->distance[0], 2 * at_plain->distance[0]);
}

// A ridge: two 40-degree ramps meeting at the top, between flat ground on both sides. With a slope
// limit of 45 degrees the far side is reached over the ridge; with 35 the ramps are cliffs and it
// is cut off (the ramps span the whole width).
TEST(TravelCostTest, MaxSlopeBlocksSteeperFaces) {
  GridSpec spec;
  spec.cells_x = 12;
  spec.cells_y = 4;
  spec.width = 12;
  spec.height = 4;
  MeshData data = MakeGrid(spec);
  const double rise = std::tan(40 * M_PI / 180);
  for (size_t v = 0; v < data.positions.size() / 3; ++v) {
    const double x = data.positions[3 * v];
    data.positions[3 * v + 2] = rise * std::max(0.0, 2 - std::abs(x - 6));  // ramps on 4 < x < 8
  }
  const TriangleMesh mesh = BuildMesh(data);
  const std::vector<double> slope = FaceSlopesDeg(mesh);
  double steepest = 0;
  for (double s : slope) steepest = std::max(steepest, s);
  EXPECT_NEAR(steepest, 40, 1e-9);
  const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(0)};  // x = 0
  const uint32_t far = 12;                                                // x = 12, y = 0
  GeodesicOptions climb = Travel(3.6, 0.1), cliff = Travel(3.6, 0.1);
  climb.travel->max_slope_deg = 45;
  cliff.travel->max_slope_deg = 35;
  absl::StatusOr<DistanceField> a = ComputeDistanceField(mesh, sources, climb);
  absl::StatusOr<DistanceField> b = ComputeDistanceField(mesh, sources, cliff);
  ASSERT_TRUE(a.ok() && b.ok()) << a.status() << b.status();
  // Over the ridge: 8 m of flat ground and two ramps of 2 / cos(40 deg) m each.
  const double over = 8 + 2 * 2 / std::cos(40 * M_PI / 180);
  EXPECT_GE(a->distance[far], over * (1 - 1e-12));
  EXPECT_LE(a->distance[far], over * 1.1);
  EXPECT_EQ(b->distance[far], kInf);
  EXPECT_LT(b->distance[3], kInf);  // x = 3: before the ramps
}

// A matrix's entries are the point values of its rows; a symmetric matrix is symmetric.
TEST(TravelCostTest, MatrixRowsArePointValues) {
  const TriangleMesh mesh = SquarePlane(5, 50);
  const std::vector<SurfacePoint> points = {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(17),
                                            SurfacePoint::InFace(9, 0.3, 0.3, 0.4)};
  MatrixOptions options;
  options.solver = Travel(4);
  options.threads = 1;
  absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(mesh, points, points, options);
  ASSERT_TRUE(m.ok()) << m.status();
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(m->values[i * 3 + i], 0);
    for (size_t j = 0; j < 3; ++j) EXPECT_EQ(m->values[i * 3 + j], m->values[j * 3 + i]);
  }
  absl::StatusOr<PointValues> row = ComputePointValues(mesh, {{points[0]}, points, options.solver});
  ASSERT_TRUE(row.ok()) << row.status();
  for (size_t j = 1; j < 3; ++j) EXPECT_EQ(m->values[j], row->distance[j]);
}

// Paths from `from` to `tos` under options a and b: the same times and points, bit for bit.
void ExpectSamePaths(const TriangleMesh& mesh, const SurfacePoint& from,
                     const std::vector<SurfacePoint>& tos, const GeodesicOptions& a,
                     const GeodesicOptions& b) {
  absl::StatusOr<PathsQueryResult> pa = ComputeShortestPaths(mesh, from, tos, {a});
  absl::StatusOr<PathsQueryResult> pb = ComputeShortestPaths(mesh, from, tos, {b});
  ASSERT_TRUE(pa.ok() && pb.ok()) << pa.status() << pb.status();
  for (size_t t = 0; t < tos.size(); ++t) {
    EXPECT_EQ(pa->distance[t], pb->distance[t]) << t;
    ASSERT_EQ(pa->paths[t].points.size(), pb->paths[t].points.size()) << t;
    for (size_t k = 0; k < pa->paths[t].points.size(); ++k) {
      EXPECT_EQ(pa->paths[t].points[k].position, pb->paths[t].points[k].position) << t;
    }
  }
}

// Several weights share nothing (BuildTravelSurface gives null: paths, point values and matrices
// run on regions built around their own points, the fields' engine). A Steiner graph of the
// same cost handed to queries in TravelCost::graph anyway is not read: every path, point value and
// matrix entry is bit for bit what a query building its own gives, under the query's own limits
// (max_distance, cancel); the graph would serve them by its own test (Serves), and a graph of
// other weights, another epsilon or another mesh object would not. A slope-dependent speed shares
// nothing either.
TEST(TravelCostTest, ASharedGraphAnswersAsEachQuerysOwn) {
  const TriangleMesh mesh = SquarePlane(8, 80, 0.2);
  auto weights = std::make_shared<std::vector<double>>(mesh.face_count(), 1.0);
  for (uint32_t f = 0; f < mesh.face_count(); f += 3) (*weights)[f] = 2.5;
  GeodesicOptions own = Travel(3.6, 0.05);
  own.travel->face_weight = weights;
  absl::StatusOr<std::shared_ptr<const WeightedSurface>> nothing = BuildTravelSurface(mesh, own);
  ASSERT_TRUE(nothing.ok()) << nothing.status();
  EXPECT_EQ(*nothing, nullptr);
  absl::StatusOr<WeightedOptions> weighted = WeightedOptionsFor(mesh, own);
  ASSERT_TRUE(weighted.ok()) << weighted.status();
  absl::StatusOr<WeightedSurface> built = WeightedSurface::Build(mesh, *weighted);
  ASSERT_TRUE(built.ok()) << built.status();
  const absl::StatusOr<std::shared_ptr<const WeightedSurface>> graph =
      std::make_shared<const WeightedSurface>(*std::move(built));
  GeodesicOptions shared = own;
  shared.travel->graph = *graph;
  // What decides whether a query uses it.
  auto serves = [&](const TriangleMesh& m, const GeodesicOptions& o) {
    absl::StatusOr<WeightedOptions> w = WeightedOptionsFor(m, o);
    return w.ok() && (*graph)->Serves(m, *w);
  };
  EXPECT_TRUE(serves(mesh, own));
  GeodesicOptions other = own;
  other.max_distance = 5;  // a query's limit, not the graph's
  EXPECT_TRUE(serves(mesh, other));
  other.travel->max_steiner_points = (*graph)->steiner_points();
  EXPECT_TRUE(serves(mesh, other));
  other.travel->max_steiner_points = (*graph)->steiner_points() - 1;  // the query's own error
  EXPECT_FALSE(serves(mesh, other));
  EXPECT_FALSE(serves(mesh, Travel(3.6, 0.05)));  // other weights
  other = own;
  other.travel->epsilon = 0.02;
  EXPECT_FALSE(serves(mesh, other));
  other = own;
  other.travel->max_slope_deg = 89;  // (no face here is that steep: the same weights)
  EXPECT_TRUE(serves(mesh, other));
  const TriangleMesh twin = SquarePlane(8, 80, 0.2);  // the same mesh, another object
  EXPECT_FALSE(serves(twin, own));

  const SurfacePoint from = SurfacePoint::InFace(5, 0.2, 0.3, 0.5);
  const std::vector<SurfacePoint> tos = {SurfacePoint::AtVertex(80),
                                         SurfacePoint::InFace(100, 0.6, 0.2, 0.2)};
  auto same_paths = [&](const GeodesicOptions& a, const GeodesicOptions& b) {
    ExpectSamePaths(mesh, from, tos, a, b);
  };
  same_paths(own, shared);
  const std::vector<SurfacePoint> points = {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(40),
                                            from, tos[1]};
  absl::StatusOr<PointValues> va = ComputePointValues(mesh, {{from}, points, own});
  absl::StatusOr<PointValues> vb = ComputePointValues(mesh, {{from}, points, shared});
  ASSERT_TRUE(va.ok() && vb.ok()) << va.status() << vb.status();
  EXPECT_EQ(va->distance, vb->distance);
  MatrixOptions ma, mb;
  ma.solver = own;
  mb.solver = shared;
  absl::StatusOr<DistanceMatrix> xa = ComputeDistanceMatrix(mesh, points, points, ma);
  absl::StatusOr<DistanceMatrix> xb = ComputeDistanceMatrix(mesh, points, points, mb);
  ASSERT_TRUE(xa.ok() && xb.ok()) << xa.status() << xb.status();
  EXPECT_EQ(xa->values, xb->values);

  // The query's limits, not the builder's.
  GeodesicOptions near = shared;
  near.max_distance = va->distance[1] / 2;
  absl::StatusOr<PathsQueryResult> cut = ComputeShortestPaths(mesh, from, tos, {near});
  ASSERT_TRUE(cut.ok()) << cut.status();
  EXPECT_EQ(cut->distance[0], kUnreachable);
  CancelToken cancelled;
  cancelled.Cancel();
  GeodesicOptions stop = shared;
  stop.cancel = &cancelled;
  EXPECT_TRUE(absl::IsCancelled(ComputePointValues(mesh, {{from}, points, stop}).status()));

  // Not this query's graph: other weights, another epsilon, another mesh object.
  GeodesicOptions plain = Travel(3.6, 0.05);
  GeodesicOptions stale = plain;
  stale.travel->graph = *graph;
  same_paths(plain, stale);
  absl::StatusOr<PathsQueryResult> pp = ComputeShortestPaths(mesh, from, tos, {plain});
  absl::StatusOr<PathsQueryResult> pw = ComputeShortestPaths(mesh, from, tos, {own});
  ASSERT_TRUE(pp.ok() && pw.ok());
  EXPECT_NE(pp->distance[0], pw->distance[0]);  // the weights matter here
  GeodesicOptions finer = shared;
  finer.travel->epsilon = 0.02;
  GeodesicOptions finer_own = own;
  finer_own.travel->epsilon = 0.02;
  same_paths(finer_own, finer);
  absl::StatusOr<PointValues> on_twin = ComputePointValues(twin, {{from}, points, shared});
  ASSERT_TRUE(on_twin.ok()) << on_twin.status();
  EXPECT_EQ(on_twin->distance, va->distance);

  GeodesicOptions tobler = own;
  tobler.travel->speed_model = SpeedModel::kTobler;
  tobler.travel->speed_kmh = 0;
  absl::StatusOr<std::shared_ptr<const WeightedSurface>> none = BuildTravelSurface(mesh, tobler);
  ASSERT_TRUE(none.ok()) << none.status();
  EXPECT_EQ(*none, nullptr);
}

// One weight (the exact engine, no graph): BuildTravelSurface wraps the exact engine's surface to
// be shared the same way; a query handed it answers bit for bit as one building its own, and it
// serves only queries of the same weights and window budget.
TEST(TravelCostTest, ASharedOneWeightSurfaceAnswersAsEachQuerysOwn) {
  const TriangleMesh mesh = SquarePlane(8, 80, 0.2);
  GeodesicOptions own = Travel(3.6);
  std::vector<double> weights(mesh.face_count(), 2.0);
  weights[7] = kInf;
  own.travel->face_weight = std::make_shared<std::vector<double>>(std::move(weights));
  absl::StatusOr<std::shared_ptr<const WeightedSurface>> surface = BuildTravelSurface(mesh, own);
  ASSERT_TRUE(surface.ok()) << surface.status();
  ASSERT_NE(*surface, nullptr);
  EXPECT_EQ((*surface)->steiner_points(), 0u);
  EXPECT_GT((*surface)->bytes(), mesh.MemoryBytes() / 2);  // (the union mesh, about the mesh)
  auto serves = [&](const GeodesicOptions& o) {
    absl::StatusOr<WeightedOptions> w = WeightedOptionsFor(mesh, o);
    return w.ok() && (*surface)->Serves(mesh, *w);
  };
  EXPECT_TRUE(serves(own));
  GeodesicOptions other = own;
  other.max_windows = 1000;  // another budget: its own surface
  EXPECT_FALSE(serves(other));
  EXPECT_FALSE(serves(Travel(3.6)));  // other weights

  GeodesicOptions shared = own;
  shared.travel->graph = *surface;
  const SurfacePoint from = SurfacePoint::InFace(5, 0.2, 0.3, 0.5);
  const std::vector<SurfacePoint> tos = {SurfacePoint::AtVertex(80),
                                         SurfacePoint::InFace(100, 0.6, 0.2, 0.2)};
  ExpectSamePaths(mesh, from, tos, own, shared);
  const std::vector<SurfacePoint> points = {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(40),
                                            from, tos[1]};
  absl::StatusOr<PointValues> va = ComputePointValues(mesh, {{from}, points, own});
  absl::StatusOr<PointValues> vb = ComputePointValues(mesh, {{from}, points, shared});
  ASSERT_TRUE(va.ok() && vb.ok()) << va.status() << vb.status();
  EXPECT_EQ(va->distance, vb->distance);
  // The query's own limits, not the builder's.
  GeodesicOptions near = shared;
  near.max_distance = va->distance[1] / 2;
  absl::StatusOr<PointValues> cut = ComputePointValues(mesh, {{from}, points, near});
  ASSERT_TRUE(cut.ok()) << cut.status();
  EXPECT_EQ(cut->distance[1], kUnreachable);
}

// Isolines in seconds: a 60 s line lies farther out than a 30 s one.
TEST(TravelCostTest, IsolinesAreDrawnInSeconds) {
  const TriangleMesh mesh = SquarePlane(10, 100);
  IsolineQuery query;
  query.sources = {SurfacePoint::AtVertex(0)};
  query.options = Travel(3.6);
  query.levels.levels = {30, 60};
  absl::StatusOr<Isolines> lines = ComputeIsolines(mesh, query);
  ASSERT_TRUE(lines.ok()) << lines.status();
  ASSERT_EQ(lines->levels.size(), 2u);
  // At 1 m/s from the corner, each line's points are `level` metres from it, within the bound
  // (and the grid's linear interpolation of the field).
  size_t points[2] = {0, 0};
  for (const IsolinePolyline& line : lines->polylines) {
    const size_t l = line.level == 30 ? 0 : 1;
    for (const PathPoint& p : line.points) {
      ++points[l];
      const double r = std::hypot(p.position[0], p.position[1]);
      EXPECT_LE(r, line.level * (1 + 1e-9));
      EXPECT_GE(r, line.level / 1.05 - 0.5);
    }
  }
  EXPECT_GT(points[0], 3u);
  EXPECT_GT(points[1], points[0]);
}

TEST(TravelCostTest, BadValuesAndWhatATravelCostCannotDoAreNamedErrors) {
  GridSpec spec;
  const TriangleMesh mesh = BuildMesh(MakeGrid(spec));
  const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(0)};
  auto option_of = [&](const GeodesicOptions& options) {
    absl::Status s = ComputeDistanceField(mesh, sources, options).status();
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
    return InvalidOptionOf(s);
  };
  EXPECT_EQ(option_of(Travel(0)), "travel.speed_kmh");
  EXPECT_EQ(option_of(Travel(-3)), "travel.speed_kmh");
  EXPECT_EQ(option_of(Travel(kInf)), "travel.speed_kmh");
  EXPECT_EQ(option_of(Travel(5, 0)), "travel.epsilon");
  EXPECT_EQ(option_of(Travel(5, 1)), "travel.epsilon");
  GeodesicOptions slope = Travel(5);
  slope.travel->max_slope_deg = 91;
  EXPECT_EQ(option_of(slope), "travel.max_slope_deg");
  GeodesicOptions lambda = Travel(5);
  lambda.lambda = 0.1;
  EXPECT_EQ(option_of(lambda), "travel");
  GeodesicOptions few = Travel(5);
  few.travel->face_weight = std::make_shared<std::vector<double>>(3, 1.0);
  EXPECT_EQ(option_of(few), "face_weight");
  GeodesicOptions zero = Travel(5);
  zero.travel->face_weight = std::make_shared<std::vector<double>>(mesh.face_count(), 1.0);
  std::const_pointer_cast<std::vector<double>>(zero.travel->face_weight)->at(7) = 0;
  EXPECT_EQ(option_of(zero), "face_weight[7]");

  PointQuery directions{sources, {SurfacePoint::AtVertex(5)}, Travel(5)};
  directions.directions = true;
  EXPECT_EQ(InvalidOptionOf(ComputePointValues(mesh, directions).status()), "travel");
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, sources, Travel(5));
  ASSERT_TRUE(field.ok());
  FieldQuery with_directions{sources, Travel(5), true};
  DistanceField products;
  EXPECT_EQ(InvalidOptionOf(ComputeFieldProducts(mesh, *field, with_directions, &products)),
            "travel");
  EXPECT_EQ(InvalidOptionOf(EstimateDistanceAt(mesh, *field, SurfacePoint::AtVertex(3)).status()),
            "travel");
  EXPECT_EQ(InvalidOptionOf(TracePathFromVertex(mesh, *field, 3).status()), "travel");
  DelaunayQuery delaunay{sources, Travel(5)};
  EXPECT_EQ(InvalidOptionOf(ComputeDelaunay(mesh, delaunay).status()), "travel");
}

}  // namespace
}  // namespace geodex
