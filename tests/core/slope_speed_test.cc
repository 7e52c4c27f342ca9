// Slope-dependent speed (travel cost part 2, geodex/travel_cost.h): Tobler's hiking function and
// speed tables, switchbacks on steep faces, inbound fields and asymmetric matrices, checked
// against analytic times on planes.

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "geodex/travel_cost.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"

namespace geodex {
namespace {

constexpr int kCells = 10;
constexpr double kSize = 100;  // metres

// A 100 m x 100 m plane rising `grade` (rise / run) along +y, jittered so paths cross faces.
TriangleMesh Incline(double grade, int cells = kCells, double jitter = 0.15) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = cells;
  spec.width = spec.height = kSize;
  spec.jitter = jitter;
  MeshData data = MakeGrid(spec);
  for (size_t v = 0; v < data.positions.size() / 3; ++v) {
    data.positions[3 * v + 2] = grade * data.positions[3 * v + 1];
  }
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return *std::move(mesh);
}

// The grid vertex at column i, row j (y = j x cell).
SurfacePoint GridVertex(int i, int j, int cells = kCells) {
  return SurfacePoint::AtVertex(static_cast<uint32_t>(j * (cells + 1) + i));
}

GeodesicOptions Tobler(double epsilon = 0.05, bool inbound = false) {
  GeodesicOptions options;
  options.travel = TravelCost{};
  options.travel->speed_model = SpeedModel::kTobler;
  options.travel->epsilon = epsilon;
  options.travel->inbound = inbound;
  return options;
}

// Seconds per metre at rise / run s.
double PerMetre(double s) { return 3.6 / ToblerKmh(s); }

double TimeAt(const TriangleMesh& mesh, const SurfacePoint& from, const SurfacePoint& to,
              const GeodesicOptions& options) {
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, {from}, options);
  EXPECT_TRUE(field.ok()) << field.status();
  if (!field.ok()) return -1;
  return field->distance[to.vertex];
}

TEST(SlopeSpeedTest, ToblerIsFastestOnAFivePercentDescent) {
  EXPECT_DOUBLE_EQ(ToblerKmh(-0.05), 6);
  EXPECT_NEAR(ToblerKmh(0), 6 * std::exp(-0.175), 1e-12);
  EXPECT_NEAR(ToblerKmh(0.05), ToblerKmh(-0.15), 1e-12);  // symmetric about the 5% descent
  EXPECT_LT(ToblerKmh(0.05), ToblerKmh(-0.05));
}

// Along a contour of a uniform 5% plane the slope is 0: L / Tobler(0).
TEST(SlopeSpeedTest, AlongAContourTakesLengthOverToblerAtZero) {
  const TriangleMesh mesh = Incline(0.05);
  const double t = TimeAt(mesh, GridVertex(0, 5), GridVertex(kCells, 5), Tobler());
  const double expected = kSize * PerMetre(0);
  EXPECT_NEAR(t, expected, 0.01 * expected);
}

// Obliquely across the 5% plane (about 22 degrees off the grid's rows, through jittered faces),
// with 3 Steiner points per edge (beyond the denser ones near the source, for 20 edge lengths):
// the least time is the straight line's (the plane's cost is a norm). The search crosses edges
// between Steiner points, so it stays within 0.1% (measured 0.013%); a path bent at the points
// alone is 0.2% slower at this spacing.
TEST(SlopeSpeedTest, ObliqueTimeIsCloseWithFewPointsPerEdge) {
  constexpr int kGrid = 60;
  const TriangleMesh mesh = Incline(0.05, kGrid);
  for (const auto& [i, j] : {std::pair{60, 24}, std::pair{18, 60}}) {
    const SurfacePoint from = GridVertex(0, 0, kGrid), to = GridVertex(i, j, kGrid);
    const Vec3 a = mesh.Position(from.vertex), b = mesh.Position(to.vertex);
    const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    const double expected =
        std::sqrt(dx * dx + dy * dy + dz * dz) * PerMetre(dz / std::hypot(dx, dy));
    const double t = TimeAt(mesh, from, to, Tobler(/*epsilon=*/0.25));
    EXPECT_NEAR(t, expected, 0.001 * expected) << i << " " << j;
    const double back = TimeAt(mesh, to, from, Tobler(/*epsilon=*/0.25));
    const double back_expected =
        std::sqrt(dx * dx + dy * dy + dz * dz) * PerMetre(-dz / std::hypot(dx, dy));
    EXPECT_NEAR(back, back_expected, 0.001 * back_expected) << i << " " << j;
  }
}

// Near a point source the times are small and bend most (a cone), so an error that is small
// farther out is a large share of them there: the points are graded, denser near the source
// (up to 4x within a few edge lengths). Across a 40 x 40 jittered 5% plane from its centre, with 3
// points per edge far away: every vertex 2-8 cells from the source within 0.2% of the straight
// line's time (the plane's cost is a norm; measured 0.09%). With even points it is 1.3%, and
// with graded points but no crossings between them 0.25%.
TEST(SlopeSpeedTest, TimesNearTheSourceAreCloseToo) {
  constexpr int kGrid = 40;
  const TriangleMesh mesh = Incline(0.05, kGrid);
  const SurfacePoint from = GridVertex(kGrid / 2, kGrid / 2, kGrid);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, {from}, Tobler(0.25));
  ASSERT_TRUE(field.ok()) << field.status();
  const Vec3 a = mesh.Position(from.vertex);
  double worst = 0;
  for (int j = 0; j <= kGrid; ++j) {
    for (int i = 0; i <= kGrid; ++i) {
      const int rings = std::max(std::abs(i - kGrid / 2), std::abs(j - kGrid / 2));
      if (rings < 2 || rings > 8) continue;
      const uint32_t v = GridVertex(i, j, kGrid).vertex;
      const Vec3 b = mesh.Position(v);
      const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
      const double expected =
          std::sqrt(dx * dx + dy * dy + dz * dz) * PerMetre(dz / std::hypot(dx, dy));
      worst = std::max(worst, std::abs(field->distance[v] / expected - 1));
    }
  }
  EXPECT_LT(worst, 0.002);
}

// Up and down the gradient of the same plane: each within 1% of its analytic time, and their
// ratio e^0.35. The inbound field from the bottom gives the time down to it.
TEST(SlopeSpeedTest, UpAndDownTheGradientDifferByEToThe035) {
  const double grade = 0.05;
  const TriangleMesh mesh = Incline(grade);
  const double length = kSize * std::sqrt(1 + grade * grade);  // 3D
  const SurfacePoint bottom = GridVertex(5, 0), top = GridVertex(5, kCells);
  const double up = TimeAt(mesh, bottom, top, Tobler());
  const double down = TimeAt(mesh, top, bottom, Tobler());
  const double up_expected = length * PerMetre(grade), down_expected = length * PerMetre(-grade);
  EXPECT_NEAR(up, up_expected, 0.01 * up_expected);
  EXPECT_NEAR(down, down_expected, 0.01 * down_expected);
  EXPECT_NEAR(up / down, std::exp(0.35), 0.01 * std::exp(0.35));
  // Inbound: times to reach the source. From the bottom: the time to walk down to it (within
  // the discretisation: the search crosses between Steiner points, which a search from the other
  // end approximates differently).
  const double down_inbound = TimeAt(mesh, bottom, top, Tobler(0.05, /*inbound=*/true));
  EXPECT_NEAR(down_inbound, down_expected, 0.01 * down_expected);
  const double up_inbound = TimeAt(mesh, top, bottom, Tobler(0.05, /*inbound=*/true));
  EXPECT_NEAR(up_inbound, up_expected, 0.01 * up_expected);
}

// The least time per metre of progress straight up a plane of slope angle `slope_rad` by
// symmetric zigzags at angle phi from the fall line: min over phi of cost(phi) / cos(phi).
double SwitchbackPerMetre(double slope_rad) {
  double best = PerMetre(std::tan(slope_rad));  // phi = 0: straight up
  for (int k = 1; k < 900000; ++k) {
    const double phi = k * 1e-4 * M_PI / 180;  // to 90 degrees
    const double sine = std::sin(slope_rad) * std::cos(phi);
    const double s = sine / std::sqrt(1 - sine * sine);
    best = std::min(best, PerMetre(s) / std::cos(phi));
  }
  return best;
}

// Up a uniform 45-degree plane: the switchback time (the analytic minimum over symmetric zigzags),
// far below the straight line's, whether the plane is 2 faces or 512.
TEST(SlopeSpeedTest, UpAFortyFiveDegreePlaneWalksTheSwitchbacks) {
  const double length = kSize * std::sqrt(2.0);
  const double zigzag = length * SwitchbackPerMetre(M_PI / 4);
  const double straight = length * PerMetre(1);
  ASSERT_LT(zigzag, straight / 3);  // the analytic fact the test rests on
  for (int cells : {1, 4, 16}) {
    const TriangleMesh mesh = Incline(1, cells);
    const double up = TimeAt(mesh, GridVertex(cells / 2, 0, cells),
                             GridVertex(cells / 2, cells, cells), Tobler(0.5));
    // The issue asks for 2%. Within a face the switchback is the convex envelope, so even one
    // face (sparse Steiner points, epsilon 0.5) is within 0.01%; without the envelope the graph
    // zigzags between edges and is 0.9% off on one face, 0.09% on 16 x 16 cells.
    EXPECT_NEAR(up, zigzag, 1e-4 * zigzag) << cells << " cells";
  }
  // The least-time path says the same time, and its points climb the plane.
  const TriangleMesh mesh = Incline(1, 8);
  absl::StatusOr<PathQueryResult> path =
      ComputeShortestPath(mesh, {GridVertex(4, 0, 8), GridVertex(4, 8, 8), {Tobler()}});
  ASSERT_TRUE(path.ok()) << path.status();
  EXPECT_NEAR(path->distance, zigzag, 0.02 * zigzag);
  EXPECT_NEAR(path->path.points.back().position[2], kSize, 1e-9);
}

// A speed table equal to Tobler sampled every 0.1 degrees gives Tobler's times, on a surface with
// every slope and direction (hills).
TEST(SlopeSpeedTest, AFineToblerTableGivesToblersTimes) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 12;
  spec.width = spec.height = 300;
  spec.jitter = 0.1;
  MeshData data = MakeGrid(spec);
  for (size_t v = 0; v < data.positions.size() / 3; ++v) {
    const double x = data.positions[3 * v], y = data.positions[3 * v + 1];
    data.positions[3 * v + 2] = 40 * std::sin(x / 45) * std::cos(y / 60);
  }
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  auto table = std::make_shared<std::vector<std::array<double, 2>>>();
  for (int k = -850; k <= 850; ++k) {  // (Tobler is 0 in doubles near 90 degrees)
    const double deg = k * 0.1;
    table->push_back({deg, ToblerKmh(std::tan(deg * M_PI / 180))});
  }
  GeodesicOptions tabled = Tobler();
  tabled.travel->speed_model = SpeedModel::kTable;
  tabled.travel->speed_table = table;
  const std::vector<SurfacePoint> sources = {SurfacePoint::AtVertex(0)};
  absl::StatusOr<DistanceField> a = ComputeDistanceField(*mesh, sources, Tobler());
  absl::StatusOr<DistanceField> b = ComputeDistanceField(*mesh, sources, tabled);
  ASSERT_TRUE(a.ok() && b.ok()) << a.status() << b.status();
  double worst = 0;
  for (size_t v = 1; v < a->distance.size(); ++v) {
    ASSERT_TRUE(std::isfinite(a->distance[v])) << v;
    worst = std::max(worst, std::abs(b->distance[v] / a->distance[v] - 1));
  }
  EXPECT_LT(worst, 1e-3);
  // A coarse table (walking flat-out at 5 km/h, 1 km/h at +-30 degrees, nothing steeper) is
  // another model: slower uphill than Tobler on these hills.
  GeodesicOptions coarse = tabled;
  coarse.travel->speed_table = std::make_shared<std::vector<std::array<double, 2>>>(
      std::vector<std::array<double, 2>>{{-30, 1}, {0, 5}, {30, 1}});
  absl::StatusOr<DistanceField> c = ComputeDistanceField(*mesh, sources, coarse);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_NE(c->distance[50], a->distance[50]);
}

// Matrices are row to column: up and down the 5% plane differ; each entry is the field's time.
// A one-row matrix is the field from its source bit for bit (one graph, graded near that
// source); a matrix's shared graph is graded near all its sources, so its entries differ from
// the fields' in the last digits the points' spacing governs.
TEST(SlopeSpeedTest, MatricesAreAsymmetric) {
  const TriangleMesh mesh = Incline(0.05);
  const std::vector<SurfacePoint> points = {GridVertex(5, 0), GridVertex(5, kCells)};
  absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(mesh, points, points, Tobler());
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->values[0], 0);
  EXPECT_EQ(m->values[3], 0);
  const double up = TimeAt(mesh, points[0], points[1], Tobler());
  const double down = TimeAt(mesh, points[1], points[0], Tobler());
  EXPECT_NEAR(m->values[1], up, 1e-4 * up);
  EXPECT_NEAR(m->values[2], down, 1e-4 * down);
  EXPECT_GT(m->values[1], 1.3 * m->values[2]);
  for (int row = 0; row < 2; ++row) {
    absl::StatusOr<DistanceMatrix> one =
        ComputeDistanceMatrix(mesh, {points[row]}, points, Tobler());
    ASSERT_TRUE(one.ok()) << one.status();
    EXPECT_EQ(one->values[1 - row], row == 0 ? up : down) << row;
  }
}

// A source given many times grades the shared graph once: 66 sources naming 2 points (more than
// the 64 sources the grading takes) give the 2-point matrix's rows bit for bit.
TEST(SlopeSpeedTest, RepeatedMatrixSourcesGradeTheGraphOnce) {
  const TriangleMesh mesh = Incline(0.05);
  const std::vector<SurfacePoint> points = {GridVertex(5, 0), GridVertex(5, kCells)};
  std::vector<SurfacePoint> repeated;
  for (int i = 0; i < 33; ++i) repeated.insert(repeated.end(), points.begin(), points.end());
  absl::StatusOr<DistanceMatrix> once = ComputeDistanceMatrix(mesh, points, points, Tobler());
  ASSERT_TRUE(once.ok()) << once.status();
  absl::StatusOr<DistanceMatrix> many = ComputeDistanceMatrix(mesh, repeated, points, Tobler());
  ASSERT_TRUE(many.ok()) << many.status();
  ASSERT_EQ(many->values.size(), repeated.size() * 2);
  for (size_t row = 0; row < repeated.size(); ++row) {
    for (size_t c = 0; c < 2; ++c) {
      EXPECT_EQ(many->values[row * 2 + c], once->values[(row % 2) * 2 + c]) << row << ", " << c;
    }
  }
}

// Unset, epsilon is the speed model's default: 0.125 for a slope speed (its points' spacing), 0.01
// for a constant speed (its bound); a set one is used as set, and 0 is refused by name.
TEST(SlopeSpeedTest, EpsilonDefaultsToTheSpeedModels) {
  TravelCost constant;
  constant.speed_kmh = 3.6;
  EXPECT_EQ(TravelEpsilon(constant), 0.01);
  TravelCost tobler;
  tobler.speed_model = SpeedModel::kTobler;
  EXPECT_EQ(TravelEpsilon(tobler), 0.125);
  tobler.epsilon = 0.05;
  EXPECT_EQ(TravelEpsilon(tobler), 0.05);
  const TriangleMesh mesh = Incline(0.05);
  GeodesicOptions options = Tobler();
  options.travel->epsilon.reset();
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, {GridVertex(0, 0)}, options);
  ASSERT_TRUE(field.ok()) << field.status();
  EXPECT_EQ(field->travel_epsilon, 0.125);
  options.travel->epsilon = 0;
  field = ComputeDistanceField(mesh, {GridVertex(0, 0)}, options);
  ASSERT_FALSE(field.ok());
  EXPECT_EQ(InvalidOptionOf(field.status()), "travel.epsilon") << field.status();
}

TEST(SlopeSpeedTest, BadSpeedModelsAreNamedErrors) {
  const TriangleMesh mesh = Incline(0.05, 2, 0);
  auto error_of = [&](const GeodesicOptions& options) {
    absl::StatusOr<DistanceField> f = ComputeDistanceField(mesh, {GridVertex(0, 0, 2)}, options);
    EXPECT_FALSE(f.ok());
    EXPECT_TRUE(absl::IsInvalidArgument(f.status())) << f.status();
    return InvalidOptionOf(f.status()) + ": " + std::string(f.status().message());
  };
  GeodesicOptions o = Tobler();
  o.travel->speed_kmh = 5;
  EXPECT_NE(error_of(o).find("travel.speed_kmh"), std::string::npos);
  o = Tobler();
  o.travel->speed_model = SpeedModel::kTable;
  EXPECT_NE(error_of(o).find("travel.speed_table"), std::string::npos);  // no table
  auto table = [](std::vector<std::array<double, 2>> rows) {
    return std::make_shared<std::vector<std::array<double, 2>>>(std::move(rows));
  };
  o.travel->speed_table = table({{-10, 4}, {-10, 5}});
  EXPECT_NE(error_of(o).find("travel.speed_table[1]"), std::string::npos);
  o.travel->speed_table = table({{-10, 4}, {10, 0}});
  EXPECT_NE(error_of(o).find("travel.speed_table[1]"), std::string::npos);
  o.travel->speed_table = table({{5, 4}, {10, 5}});
  EXPECT_NE(error_of(o).find("slope 0"), std::string::npos);
  o.travel->speed_table = table({{-95, 4}, {10, 5}});
  EXPECT_NE(error_of(o).find("travel.speed_table[0]"), std::string::npos);
}

}  // namespace
}  // namespace geodex
