// A DEM as an adaptive TIN (DemOptions::z_tolerance, terrain.h): the TIN honours every cell within
// Z, a plane is two triangles and exact, holes keep the grid's exact boundary, map points drop onto
// the TIN, rasters hold the exact field at the cell centres, and a stored TIN loads back the same.
// Answers are analytic (planes, the taut string round a slot) or the grid's.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "dem_fixture.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/terrain.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"

namespace geodex::terrain {
namespace {

DemOptions Tin(double z) {
  DemOptions options;
  options.z_tolerance = z;
  return options;
}

// Smooth hills on a 10 m grid, heights in metres.
double Hills(double x, double y) {
  const double u = (x - 500000) / 10, v = (5000000 - y) / 10;
  return 40 * std::sin(u / 9.0) * std::cos(v / 7.0) + 0.3 * u + 15 * std::sin(v / 23.0);
}

// The TIN build takes the solves' cancel token (DemOptions::cancel): cancelled, the read answers
// Cancelled (geodexd cancels an upload's build with its call); without one it builds.
TEST_F(DemTest, ATinBuildStopsWhenCancelled) {
  Grid g;
  g.height_at = [](double x, double y, int, int) { return Hills(x, y); };
  const std::string path = Write("cancel.tif", g);
  CancelToken cancel;
  cancel.Cancel();
  DemOptions options = Tin(0.01);
  options.cancel = &cancel;
  EXPECT_EQ(Dem::Read(path, options).status().code(), absl::StatusCode::kCancelled);
  options.cancel = nullptr;
  EXPECT_TRUE(Dem::Read(path, options).ok());
}

TEST_F(DemTest, TinOfAPlaneIsTwoTrianglesAndItsRasterIsExact) {
  Grid g;
  g.height_at = [](double x, double y, int, int) {
    return 0.1 * (x - 500000) + 0.2 * (y - 4999700);
  };
  const std::string path = Write("plane.tif", g);
  for (const double z : {1e-6, 0.5, 100.0}) {
    absl::StatusOr<Dem> dem = Dem::Read(path, Tin(z));
    ASSERT_TRUE(dem.ok()) << dem.status();
    EXPECT_TRUE(dem->is_tin());
    EXPECT_EQ(dem->mesh().vertex_count(), 4u) << z;
    EXPECT_EQ(dem->mesh().face_count(), 2u) << z;
    EXPECT_LT(dem->info().max_vertical_deviation, 1e-9);
    EXPECT_EQ(dem->info().z_tolerance, z);
    absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
    ASSERT_TRUE(mesh.ok());
    const double sx = 500123, sy = 4999811;  // a map point inside a face
    absl::StatusOr<SurfacePoint> source = dem->DropMapPoint(sx, sy);
    ASSERT_TRUE(source.ok()) << source.status();
    const std::array<double, 3> s = PositionOf(dem->mesh(), *source);
    EXPECT_NEAR(s[2], 0.1 * (sx - 500000) + 0.2 * (sy - 4999700), 1e-9);
    absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {*source});
    ASSERT_TRUE(field.ok());
    GeodesicOptions exact;
    absl::StatusOr<CellValues> cells = SampleCells(*dem, *field, &*mesh, &exact);
    ASSERT_TRUE(cells.ok()) << cells.status();
    EXPECT_FALSE(cells->estimated);
    // Every cell: the straight 3D distance on the plane from the source to its centre.
    double worst = 0;
    for (int row = 0; row < g.height; ++row) {
      for (int col = 0; col < g.width; ++col) {
        const double x = g.x0 + (col + 0.5) * g.dx, y = g.y0 - (row + 0.5) * g.dy;
        const double want = Dist(s, {x, y, g.height_at(x, y, col, row)});
        worst = std::max(worst, std::abs(cells->distance[size_t(row) * g.width + col] - want));
      }
    }
    EXPECT_LT(worst, 1e-9) << z;
  }
}

TEST_F(DemTest, EveryCellIsWithinZOfTheTin) {
  Grid g;
  g.width = 120;
  g.height = 90;
  g.height_at = [](double x, double y, int, int) { return Hills(x, y); };
  const std::string path = Write("hills.tif", g);
  size_t previous = 0;
  for (const double z : {2.0, 0.5, 0.1}) {  // a smaller Z never has fewer vertices
    absl::StatusOr<Dem> dem = Dem::Read(path, Tin(z));
    ASSERT_TRUE(dem.ok()) << dem.status();
    EXPECT_GE(dem->mesh().vertex_count(), previous);
    previous = dem->mesh().vertex_count();
    EXPECT_LT(dem->mesh().vertex_count(), size_t(g.width) * g.height / (z >= 0.5 ? 3 : 1)) << z;
    EXPECT_LE(dem->info().max_vertical_deviation, z);
    EXPECT_GT(dem->info().max_vertical_deviation, 0.5 * z);  // measured, not assumed
    EXPECT_LE(dem->info().rms_vertical_deviation, dem->info().max_vertical_deviation);
    // Checked here against the raster: the TIN's height below each cell centre.
    double worst = 0, sum2 = 0;
    for (uint32_t row = 0; row < uint32_t(g.height); ++row) {
      for (uint32_t col = 0; col < uint32_t(g.width); ++col) {
        absl::StatusOr<SurfacePoint> p = dem->CellPoint(col, row);
        ASSERT_TRUE(p.ok()) << p.status();
        const std::array<double, 3> at = PositionOf(dem->mesh(), *p);
        const double x = g.x0 + (col + 0.5) * g.dx, y = g.y0 - (row + 0.5) * g.dy;
        EXPECT_NEAR(at[0], x, 1e-6);
        EXPECT_NEAR(at[1], y, 1e-6);
        const double dz = std::abs(at[2] - Hills(x, y));
        worst = std::max(worst, dz);
        sum2 += dz * dz;
      }
    }
    EXPECT_LE(worst, z * (1 + 1e-9)) << z;
    EXPECT_NEAR(worst, dem->info().max_vertical_deviation, 1e-9 * (1 + worst));
    EXPECT_NEAR(std::sqrt(sum2 / (g.width * g.height)), dem->info().rms_vertical_deviation,
                1e-9 * (1 + worst));
  }
}

// The flat slot of NodataHoleIsGoneAround, as a TIN: two triangles with the slot cut out along the
// grid's own hole boundary, so the detour is the grid's, exactly.
TEST_F(DemTest, TinHolesKeepTheGridsExactBoundary) {
  const Grid g = SlotGrid();
  const std::string path = Write("slot.tif", g);
  absl::StatusOr<Dem> grid = Dem::Read(path);
  absl::StatusOr<Dem> tin = Dem::Read(path, Tin(0.25));
  ASSERT_TRUE(grid.ok() && tin.ok()) << tin.status();
  EXPECT_LT(tin->mesh().face_count(), grid->mesh().face_count() / 10);
  auto centre = [&](double col, double row) {
    return std::array<double, 3>{g.x0 + (col + 0.5) * g.dx, g.y0 - (row + 0.5) * g.dy, 0};
  };
  const std::array<double, 3> a = centre(10, 15), b = centre(20, 15);
  const double want = Dist(a, centre(13, 4)) + Dist(centre(13, 4), centre(15, 4)) +
                      Dist(centre(15, 4), centre(16, 5)) + Dist(centre(16, 5), b);
  for (const Dem* dem : {&*grid, &*tin}) {
    absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
    ASSERT_TRUE(mesh.ok());
    absl::StatusOr<SurfacePoint> pa = dem->DropMapPoint(a[0], a[1]);
    absl::StatusOr<SurfacePoint> pb = dem->DropMapPoint(b[0], b[1]);
    ASSERT_TRUE(pa.ok() && pb.ok());
    absl::StatusOr<std::vector<std::pair<double, uint32_t>>> d =
        ComputeExactDistancesAt(*mesh, {*pa}, {*pb});
    ASSERT_TRUE(d.ok()) << d.status();
    EXPECT_NEAR((*d)[0].first, want, 1e-9 * want) << (dem == &*tin ? "tin" : "grid");
    // In the slot: a hole; on its edge: the surface.
    const std::array<double, 3> in = centre(14.5, 20), edge = centre(13, 12);
    EXPECT_NE(dem->DropMapPoint(in[0], in[1]).status().message().find("in a hole"),
              std::string::npos);
    EXPECT_TRUE(dem->DropMapPoint(edge[0], edge[1]).ok());
  }
  // The same cells have surface, and the rasters' fields agree (a plane: exactly).
  absl::StatusOr<TriangleMesh> grid_mesh = TriangleMesh::Build(grid->mesh());
  absl::StatusOr<TriangleMesh> tin_mesh = TriangleMesh::Build(tin->mesh());
  ASSERT_TRUE(grid_mesh.ok() && tin_mesh.ok());
  absl::StatusOr<SurfacePoint> gs = grid->DropMapPoint(a[0], a[1]);
  absl::StatusOr<SurfacePoint> ts = tin->DropMapPoint(a[0], a[1]);
  ASSERT_TRUE(gs.ok() && ts.ok());
  absl::StatusOr<DistanceField> gf = ComputeDistanceField(*grid_mesh, {*gs});
  absl::StatusOr<DistanceField> tf = ComputeDistanceField(*tin_mesh, {*ts});
  ASSERT_TRUE(gf.ok() && tf.ok());
  GeodesicOptions exact;
  absl::StatusOr<CellValues> gc = SampleCells(*grid, *gf, &*grid_mesh, &exact);
  absl::StatusOr<CellValues> tc = SampleCells(*tin, *tf, &*tin_mesh, &exact);
  ASSERT_TRUE(gc.ok() && tc.ok()) << tc.status();
  EXPECT_EQ(gc->hole, tc->hole);
  EXPECT_EQ(std::count(tc->hole.begin(), tc->hole.end(), 1), 2 * 25);
  for (size_t c = 0; c < gc->distance.size(); ++c) {
    if (gc->hole[c]) continue;
    EXPECT_NEAR(tc->distance[c], gc->distance[c], 1e-9 * (1 + gc->distance[c])) << c;
  }
}

TEST_F(DemTest, TinRastersAgreeWithTheGridsAndAStoredTinLoadsTheSame) {
  Grid g;
  g.width = 100;
  g.height = 80;
  g.has_nodata = true;
  g.height_at = [&](double x, double y, int col, int row) {
    return (col - 60) * (col - 60) + (row - 30) * (row - 30) < 64 ? g.nodata : Hills(x, y);
  };
  const std::string path = Write("lake.tif", g);
  absl::StatusOr<Dem> grid = Dem::Read(path);
  absl::StatusOr<Dem> tin = Dem::Read(path, Tin(0.05));
  ASSERT_TRUE(grid.ok() && tin.ok()) << tin.status();
  absl::StatusOr<TriangleMesh> grid_mesh = TriangleMesh::Build(grid->mesh());
  absl::StatusOr<TriangleMesh> tin_mesh = TriangleMesh::Build(tin->mesh());
  ASSERT_TRUE(grid_mesh.ok() && tin_mesh.ok());
  const double sx = 500105, sy = 4999405;
  absl::StatusOr<DistanceField> gf =
      ComputeDistanceField(*grid_mesh, {*grid->DropMapPoint(sx, sy)});
  absl::StatusOr<DistanceField> tf = ComputeDistanceField(*tin_mesh, {*tin->DropMapPoint(sx, sy)});
  ASSERT_TRUE(gf.ok() && tf.ok());
  GeodesicOptions exact;
  absl::StatusOr<CellValues> gc = SampleCells(*grid, *gf, &*grid_mesh, &exact);
  absl::StatusOr<CellValues> tc = SampleCells(*tin, *tf, &*tin_mesh, &exact);
  absl::StatusOr<CellValues> te = SampleCells(*tin, *tf, &*tin_mesh);  // the estimate
  ASSERT_TRUE(gc.ok() && tc.ok() && te.ok());
  EXPECT_EQ(gc->hole, tc->hole);
  EXPECT_TRUE(te->estimated);
  double largest = 0, worst = 0;
  for (size_t c = 0; c < gc->distance.size(); ++c) {
    if (!gc->hole[c]) largest = std::max(largest, gc->distance[c]);
  }
  for (size_t c = 0; c < gc->distance.size(); ++c) {
    if (gc->hole[c]) continue;
    worst = std::max(worst, std::abs(tc->distance[c] - gc->distance[c]));
    EXPECT_EQ(tc->source[c], 0u);
  }
  EXPECT_LT(worst, 5e-4 * largest);  // within the bound at every cell

  // Stored and loaded again (geodexd keeps the mesh and its map): the same cells and drops.
  absl::StatusOr<Dem> loaded = Dem::FromMesh(tin->mesh(), tin->info());
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  EXPECT_TRUE(loaded->is_tin());
  for (uint32_t row = 0; row < uint32_t(g.height); row += 3) {
    for (uint32_t col = 0; col < uint32_t(g.width); col += 3) {
      absl::StatusOr<SurfacePoint> a = tin->CellPoint(col, row), b = loaded->CellPoint(col, row);
      ASSERT_EQ(a.ok(), b.ok());
      if (a.ok()) {
        EXPECT_EQ(SurfacePointToString(*a), SurfacePointToString(*b));
      }
    }
  }
  std::mt19937 random(7);
  std::uniform_real_distribution<double> ux(g.x0, g.x0 + g.width * g.dx);
  std::uniform_real_distribution<double> uy(g.y0 - g.height * g.dy, g.y0);
  int dropped = 0;
  for (int k = 0; k < 300; ++k) {
    const double x = ux(random), y = uy(random);
    absl::StatusOr<SurfacePoint> a = tin->DropMapPoint(x, y), b = loaded->DropMapPoint(x, y);
    ASSERT_EQ(a.ok(), b.ok()) << x << " " << y;
    if (!a.ok()) continue;
    ++dropped;
    EXPECT_EQ(SurfacePointToString(*a), SurfacePointToString(*b));
    const std::array<double, 3> at = PositionOf(tin->mesh(), *a);  // straight below (x, y)
    EXPECT_NEAR(at[0], x, 1e-6);
    EXPECT_NEAR(at[1], y, 1e-6);
  }
  EXPECT_GT(dropped, 200);
}

// Terrain's one check of DemOptions (ValidateDemOptions, which Dem::Read runs) names the option as
// data, in no caller's words: the CLI says --z-tolerance, geodexd metadata.dem.z_tolerance
// (tests/cli, tests/server).
TEST_F(DemTest, BadZToleranceIsRefusedNamingTheFlag) {
  Grid g;
  g.height_at = [](double, double, int, int) { return 1.0; };
  const std::string path = Write("flat.tif", g);
  for (const double z :
       {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    absl::StatusOr<Dem> dem = Dem::Read(path, Tin(z));
    EXPECT_EQ(dem.status().code(), absl::StatusCode::kInvalidArgument) << z;
    EXPECT_EQ(InvalidOptionOf(dem.status()), "z_tolerance") << dem.status();
    EXPECT_EQ(dem.status().message().find("--"), std::string::npos) << dem.status();
  }
  DemOptions step;
  step.step = 0;
  EXPECT_EQ(InvalidOptionOf(ValidateDemOptions(step)), "step");
  DemOptions width;
  width.barrier_width = -1;
  EXPECT_EQ(InvalidOptionOf(ValidateDemOptions(width)), "barrier_width");
  EXPECT_TRUE(ValidateDemOptions(DemOptions{}).ok());
}

}  // namespace
}  // namespace geodex::terrain
