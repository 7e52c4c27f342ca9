// Friction for travel cost (geodex/friction.h): polygons (GeoJSON text or a file) and rasters give
// each face of a DEM's mesh the value under its centroid; bad files are errors naming the problem.

#include "geodex/friction.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "dem_fixture.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/terrain.h"
#include "geodex/triangle_mesh.h"

namespace geodex::terrain {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The face's centroid in mesh coordinates.
std::array<double, 2> Centre(const MeshData& mesh, size_t f) {
  std::array<double, 2> c{0, 0};
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 2; ++j) c[j] += mesh.positions[3 * size_t{mesh.faces[3 * f + k]} + j] / 3;
  }
  return c;
}

Grid Flat() {
  Grid g;  // EPSG:32633, 40 x 30 cells of 10 m from (500000, 5000000) south-east
  g.height_at = [](double, double, int, int) { return 100.0; };
  return g;
}

// A rectangle of friction 4 over x in [500100, 500200] (the DEM's CRS named by an identifier), a
// square of friction 2 overlapping its corner: faces take the largest value under their centroid,
// 1 outside; travel times across the rectangle grow accordingly.
TEST_F(DemTest, PolygonsGiveEachFaceTheFrictionUnderItsCentre) {
  absl::StatusOr<Dem> dem = Dem::Read(Write("flat.tif", Flat()));
  ASSERT_TRUE(dem.ok()) << dem.status();
  const std::string geojson = R"({"type": "FeatureCollection",
    "crs": {"type": "name", "properties": {"name": "EPSG:32633"}},
    "features": [
      {"type": "Feature", "properties": {"friction": 4}, "geometry": {"type": "Polygon",
       "coordinates": [[[500100, 4999700], [500200, 4999700], [500200, 5000000], [500100, 5000000],
                        [500100, 4999700]]]}},
      {"type": "Feature", "properties": {"friction": 2.5}, "geometry": {"type": "Polygon",
       "coordinates": [[[500150, 4999900], [500300, 4999900], [500300, 5000000], [500150, 5000000],
                        [500150, 4999900]]]}}]})";
  absl::StatusOr<std::vector<double>> w =
      FrictionFromGeoJson(dem->mesh(), geojson, &dem->info(), "--friction");
  ASSERT_TRUE(w.ok()) << w.status();
  ASSERT_EQ(w->size(), dem->mesh().faces.size() / 3);
  size_t fours = 0, twos = 0;
  for (size_t f = 0; f < w->size(); ++f) {
    const auto [x, y] = Centre(dem->mesh(), f);  // the mesh is the CRS's own metres
    const bool in_rect = x > 500100 && x < 500200;
    const bool in_square = x > 500150 && x < 500300 && y > 4999900;
    const double expected = in_rect ? 4 : in_square ? 2.5 : 1;
    EXPECT_EQ((*w)[f], expected) << "face " << f << " at " << x << " " << y;
    fours += expected == 4;
    twos += expected == 2.5;
  }
  EXPECT_GT(fours, 100u);
  EXPECT_GT(twos, 10u);

  // A feature without a friction, a line or a friction of 0 is an error naming it, whether the
  // regions give faces their values, are cut into the mesh, or are cut in as the DEM is read.
  const std::string no_value = R"({"type": "Feature", "properties": {"name": "x"},
    "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 0]]]}})";
  const std::string line = R"({"type": "Feature", "properties": {"friction": 3},
    "geometry": {"type": "LineString", "coordinates": [[15, 45], [15.1, 45]]}})";
  const std::string zero = R"({"type": "Feature", "properties": {"friction": 0},
    "geometry": {"type": "Polygon", "coordinates": [[[15, 45], [15.1, 45], [15, 45.1], [15, 45]]]}})";
  absl::Status s;
  for (const auto& [geojson, why] : {std::pair{no_value, "no numeric \"friction\""},
                                     std::pair{line, "friction regions are polygons"},
                                     std::pair{zero, "friction must be > 0"}}) {
    s = FrictionFromGeoJson(dem->mesh(), geojson, &dem->info(), "--friction").status();
    EXPECT_NE(s.message().find(why), std::string::npos) << s;
    s = CutFrictionOutlines(dem->mesh(), geojson, &dem->info(), "--friction", nullptr).status();
    EXPECT_NE(s.message().find(why), std::string::npos) << s;
    DemOptions options;
    options.friction_file = (dir_ / "regions.geojson").string();
    std::ofstream(options.friction_file) << geojson;
    s = Dem::Read(Write("flat.tif", Flat()), options).status();
    EXPECT_NE(s.message().find(why), std::string::npos) << s;
    EXPECT_NE(s.message().find("--friction " + options.friction_file), std::string::npos) << s;
  }
  const std::string link = R"({"type": "FeatureCollection", "crs": {"type": "link",
    "properties": {"href": "http://example.com/crs"}}, "features": []})";
  s = FrictionFromGeoJson(dem->mesh(), link, &dem->info(), "--friction").status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
}

// A raster on the DEM's own grid with friction 1 + column / 10 and a nodata column: every face
// takes the value of the cell under its centroid, nodata impassable.
TEST_F(DemTest, ARasterGivesEachFaceTheCellUnderItsCentre) {
  const Grid flat = Flat();
  absl::StatusOr<Dem> dem = Dem::Read(Write("flat.tif", flat));
  ASSERT_TRUE(dem.ok()) << dem.status();
  Grid friction = flat;
  friction.has_nodata = true;
  friction.height_at = [&](double, double, int col, int) {
    return col == 20 ? friction.nodata : 1 + col / 10.0;
  };
  absl::StatusOr<std::vector<double>> w =
      ReadFrictionFile(dem->mesh(), Write("friction.tif", friction), dem->info(), "--friction");
  ASSERT_TRUE(w.ok()) << w.status();
  for (size_t f = 0; f < w->size(); ++f) {
    const int col = static_cast<int>(std::floor((Centre(dem->mesh(), f)[0] - flat.x0) / flat.dx));
    EXPECT_EQ((*w)[f], col == 20 ? kInf : 1 + col / 10.0) << "face " << f;
  }

  // Another CRS, a raster short of the DEM, a value of 0: errors naming what is wrong.
  Grid other = friction;
  other.epsg = 32632;
  absl::Status s =
      ReadFrictionFile(dem->mesh(), Write("other.tif", other), dem->info(), "--friction").status();
  EXPECT_NE(s.message().find("is not the DEM's"), std::string::npos) << s;
  Grid small = friction;
  small.width = 20;
  s = ReadFrictionFile(dem->mesh(), Write("small.tif", small), dem->info(), "--friction").status();
  EXPECT_NE(s.message().find("does not cover the DEM"), std::string::npos) << s;
  Grid zero = friction;
  zero.height_at = [](double, double, int col, int row) {
    return col == 3 && row == 4 ? 0.0 : 1.0;
  };
  s = ReadFrictionFile(dem->mesh(), Write("zero.tif", zero), dem->info(), "--friction").status();
  EXPECT_NE(s.message().find("cell (column 3, row 4) has friction 0"), std::string::npos) << s;
}

// Travel time across the DEM through a friction-4 band costs what the band says: a field from the
// west edge reaches the east edge later by 3 x the band's width at 1 m/s (within the bound).
TEST_F(DemTest, FrictionSlowsTravelAcrossItsBand) {
  absl::StatusOr<Dem> dem = Dem::Read(Write("flat.tif", Flat()));
  ASSERT_TRUE(dem.ok()) << dem.status();
  const std::string band = R"({"type": "Feature", "properties": {"friction": 4},
    "crs": {"type": "name", "properties": {"name": "EPSG:32633"}},
    "geometry": {"type": "Polygon", "coordinates": [[[500100, 4999000], [500200, 4999000],
                 [500200, 5001000], [500100, 5001000], [500100, 4999000]]]}})";
  absl::StatusOr<std::vector<double>> w =
      FrictionFromGeoJson(dem->mesh(), band, &dem->info(), "--friction");
  ASSERT_TRUE(w.ok()) << w.status();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
  ASSERT_TRUE(mesh.ok());
  GeodesicOptions options;
  options.travel = TravelCost{};
  options.travel->speed_kmh = 3.6;
  options.travel->epsilon = 0.05;
  absl::StatusOr<DistanceField> plain =
      ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, options);
  options.travel->face_weight = std::make_shared<const std::vector<double>>(*w);
  absl::StatusOr<DistanceField> slowed =
      ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, options);
  ASSERT_TRUE(plain.ok() && slowed.ok()) << plain.status() << slowed.status();
  // Vertex 39: the north-east corner cell, 390 m east along the top row. The band's faces are
  // those whose centroids fall inside it: the first row's crossing is 100 m give or take a cell.
  const double extra = slowed->distance[39] - plain->distance[39];
  EXPECT_GT(extra, 3 * 90 * 0.95);
  EXPECT_LT(extra, 3 * 110 * 1.05);
}

// Friction outlines cut into the mesh (CutFrictionOutlines): a half-plane of friction 4 whose
// boundary runs 20 degrees off the grid's axes. Every face of the cut mesh lies on one side of it
// (on the uncut grid the centroid rule puts faces across it), the stored DEM comes back, and the
// least time from a point on one side to a point on the other is Snell's law's minimum within the
// bound (opt <= time <= 1.05 opt; a raster of the same region on the uncut grid gives 2.9% less).
TEST_F(DemTest, OutlinesCutIntoTheMeshMakeRegionBoundariesExact) {
  absl::StatusOr<Dem> dem = Dem::Read(Write("flat.tif", Flat()));
  ASSERT_TRUE(dem.ok()) << dem.status();
  const double kSin = std::sin(20 * M_PI / 180), kCos = std::cos(20 * M_PI / 180);
  const double x0 = 500200, y0 = 4999850;  // a point of the boundary; it runs along (kSin, kCos)
  auto on_line = [&](double s) { return std::array<double, 2>{x0 + s * kSin, y0 + s * kCos}; };
  const auto a = on_line(-400), b = on_line(400);
  const std::string geojson = absl::StrFormat(
      R"({"type": "Feature", "properties": {"friction": 4},
      "crs": {"type": "name", "properties": {"name": "EPSG:32633"}},
      "geometry": {"type": "Polygon", "coordinates": [[[%.17g, %.17g], [%.17g, %.17g],
                   [%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g]]]}})",
      a[0], a[1], a[0] + 1000, a[1], b[0] + 1000, b[1], b[0], b[1], a[0], a[1]);
  // East of the boundary (the friction side) is > 0.
  auto side = [&](const MeshData& m, uint32_t v) {
    return (m.positions[3 * size_t{v}] - x0) * kCos - (m.positions[3 * size_t{v} + 1] - y0) * kSin;
  };
  auto faces_across = [&](const MeshData& m, const std::vector<double>& w) {
    size_t across = 0;
    for (size_t f = 0; f < w.size(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const double d = side(m, m.faces[3 * f + k]);
        across += (w[f] == 4 && d < -1e-6) || (w[f] == 1 && d > 1e-6);
      }
    }
    return across;
  };
  absl::StatusOr<std::vector<double>> uncut =
      FrictionFromGeoJson(dem->mesh(), geojson, &dem->info(), "--friction");
  ASSERT_TRUE(uncut.ok()) << uncut.status();
  EXPECT_GT(faces_across(dem->mesh(), *uncut), 10u);  // what the cut is for

  CutStats stats;
  absl::StatusOr<MeshData> cut =
      CutFrictionOutlines(dem->mesh(), geojson, &dem->info(), "--friction", &stats);
  ASSERT_TRUE(cut.ok()) << cut.status();
  EXPECT_GT(stats.faces_split, 30u);
  EXPECT_EQ(stats.faces_removed, 0u);
  absl::StatusOr<std::vector<double>> w =
      FrictionFromGeoJson(*cut, geojson, &dem->info(), "--friction");
  ASSERT_TRUE(w.ok()) << w.status();
  EXPECT_EQ(faces_across(*cut, *w), 0u);
  absl::StatusOr<Dem> stored = Dem::FromMesh(*cut, dem->info());
  ASSERT_TRUE(stored.ok()) << stored.status();

  // Snell: from S (friction 1) to T (friction 4), crossing the boundary at on_line(s).
  const std::array<double, 2> S = {500050, 4999850}, T = {500330, 4999780};
  auto cost = [&](double s) {
    const auto p = on_line(s);
    return std::hypot(p[0] - S[0], p[1] - S[1]) + 4 * std::hypot(T[0] - p[0], T[1] - p[1]);
  };
  double lo = -400, hi = 400;  // convex in s: golden section
  for (int i = 0; i < 200; ++i) {
    const double m1 = lo + (hi - lo) * 0.382, m2 = lo + (hi - lo) * 0.618;
    (cost(m1) < cost(m2) ? hi : lo) = cost(m1) < cost(m2) ? m2 : m1;
  }
  const double optimum = cost((lo + hi) / 2);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*cut);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  absl::StatusOr<SurfacePoint> from = stored->DropMapPoint(S[0], S[1]);
  absl::StatusOr<SurfacePoint> to = stored->DropMapPoint(T[0], T[1]);
  ASSERT_TRUE(from.ok() && to.ok()) << from.status() << to.status();
  GeodesicOptions options;
  options.travel = TravelCost{};
  options.travel->speed_kmh = 3.6;  // 1 m/s: seconds are cost
  options.travel->epsilon = 0.05;
  options.travel->face_weight = std::make_shared<const std::vector<double>>(*w);
  absl::StatusOr<std::vector<std::pair<double, uint32_t>>> t =
      ComputeExactDistancesAt(*mesh, {*from}, {*to}, options);
  ASSERT_TRUE(t.ok()) << t.status();
  EXPECT_GE((*t)[0].first, optimum * (1 - 1e-9));
  EXPECT_LE((*t)[0].first, optimum * 1.05);
  std::printf("Snell across a cut outline: optimum %.6f, engine %.6f (1 + %.3g)\n", optimum,
              (*t)[0].first, (*t)[0].first / optimum - 1);
}

// DemOptions::friction_snap: a rectangle of friction 4 whose west side runs 0.05 m east of a
// column of cell centres (the mesh's vertices, 10 m apart). Cut in exactly, it leaves new
// vertices 0.05 m from those (slivers); snapped at 0.1 (discs of 1 m), the side runs through the
// column and no new vertex comes within 1 m of a grid vertex. The faces' values
// (Dem::face_friction) follow the outline as cut: exactly the drawn area unsnapped, the drawn area
// plus what the snap added (0.05 m x 150 m along the column and two 5 m tapers) snapped. A second
// region (friction 2) runs 0.05 m from another column from 1000 km south of the DEM to 1000 km
// north of it: only its part over the mesh is walked, and it is snapped there all the same.
TEST_F(DemTest, SnappedOutlinesRunThroughNearbyVertices) {
  const std::string path = Write("flat.tif", Flat());
  const double west = 500105.05, east = 500208, south = 4999800, north = 4999960;
  const std::string regions = (dir_ / "rectangle.geojson").string();
  const double far_west = 500305.05, far_south = 4e6, far_north = 6e6, far_east = 6e5;
  std::ofstream(regions) << absl::StrFormat(
      R"({"type": "FeatureCollection",
      "crs": {"type": "name", "properties": {"name": "EPSG:32633"}}, "features": [
      {"type": "Feature", "properties": {"friction": 4},
      "geometry": {"type": "Polygon", "coordinates": [[[%.17g, %.17g], [%.17g, %.17g],
                   [%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g]]]}},
      {"type": "Feature", "properties": {"friction": 2},
      "geometry": {"type": "Polygon", "coordinates": [[[%.17g, %.17g], [%.17g, %.17g],
                   [%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g]]]}}]})",
      west, south, east, south, east, north, west, north, west, south, far_west, far_south,
      far_east, far_south, far_east, far_north, far_west, far_north, far_west, far_south);
  absl::StatusOr<Dem> grid = Dem::Read(path);
  ASSERT_TRUE(grid.ok()) << grid.status();
  const size_t grid_vertices = grid->mesh().vertex_count();
  // The nearest new vertex to a grid vertex (cell centres at 500005 + 10 i, 4999995 - 10 j).
  auto closest_new = [&](const MeshData& m) {
    double closest = std::numeric_limits<double>::infinity();
    for (size_t v = grid_vertices; v < m.vertex_count(); ++v) {
      const double x = m.positions[3 * v], y = m.positions[3 * v + 1];
      const double gx = 500005 + 10 * std::round((x - 500005) / 10);
      const double gy = 4999995 - 10 * std::round((4999995 - y) / 10);
      closest = std::min(closest, std::hypot(x - gx, y - gy));
    }
    return closest;
  };
  // The x-y area of the faces of friction `value`.
  auto friction_area = [&](const Dem& dem, double value) {
    const MeshData& m = dem.mesh();
    EXPECT_EQ(dem.face_friction().size(), m.face_count());
    double area = 0;
    for (size_t f = 0; f < m.face_count() && f < dem.face_friction().size(); ++f) {
      const double* a = &m.positions[3 * size_t{m.faces[3 * f]}];
      const double* b = &m.positions[3 * size_t{m.faces[3 * f + 1]}];
      const double* c = &m.positions[3 * size_t{m.faces[3 * f + 2]}];
      const double w = dem.face_friction()[f];
      EXPECT_TRUE(w == 1 || w == 2 || w == 4) << w;
      if (w == value) {
        area += std::abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) / 2;
      }
    }
    return area;
  };
  const double drawn = (east - west) * (north - south);
  // The mesh spans the cell centres: x in [500005, 500395], y in [4999705, 4999995].
  const double drawn_far = (500395 - far_west) * 290, snapped_far = (500395 - 500305) * 290;

  DemOptions exact;
  exact.friction_file = regions;
  absl::StatusOr<Dem> cut = Dem::Read(path, exact);
  ASSERT_TRUE(cut.ok()) << cut.status();
  EXPECT_LT(closest_new(cut->mesh()), 0.1);  // the slivers
  EXPECT_NEAR(friction_area(*cut, 4), drawn, 1e-6 * drawn);
  EXPECT_NEAR(friction_area(*cut, 2), drawn_far, 1e-6 * drawn_far);

  DemOptions snapped = exact;
  snapped.friction_snap = 0.1;
  absl::StatusOr<Dem> snap = Dem::Read(path, snapped);
  ASSERT_TRUE(snap.ok()) << snap.status();
  EXPECT_GE(closest_new(snap->mesh()), 1.0);
  EXPECT_LT(snap->mesh().vertex_count(), cut->mesh().vertex_count());
  const double added = 0.05 * (north - south - 10) + 2 * (0.5 * 0.05 * 5);
  EXPECT_NEAR(friction_area(*snap, 4), drawn + added, 1e-6 * drawn);
  EXPECT_NEAR(friction_area(*snap, 2), snapped_far, 1e-6 * drawn_far);

  // Out of range, or nothing to snap: errors naming the option as data (the CLI names its flag,
  // tests/cli/travel_cli_test.sh).
  for (double bad : {-0.1, 0.3, std::numeric_limits<double>::quiet_NaN()}) {
    DemOptions options = exact;
    options.friction_snap = bad;
    absl::Status s = Dem::Read(path, options).status();
    EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
    EXPECT_EQ(InvalidOptionOf(s), "friction_snap") << s;
    EXPECT_EQ(ValidateDemOptions(options), s);
  }
  // Hostile shapes: an empty ring, and a triangle reaching 1e300 m out. Snapped, they are cut
  // in or refused by name, in bounded time (the walk clipped to the mesh; ASan sees no read of an
  // empty ring).
  const std::string hostile = (dir_ / "hostile.geojson").string();
  std::ofstream(hostile) << R"({"type": "FeatureCollection",
      "crs": {"type": "name", "properties": {"name": "EPSG:32633"}}, "features": [
      {"type": "Feature", "properties": {"friction": 3},
       "geometry": {"type": "Polygon", "coordinates": [[]]}},
      {"type": "Feature", "properties": {"friction": 2}, "geometry": {"type": "Polygon",
       "coordinates": [[[500105.05, 4999800], [1e300, 4999800], [1e300, 1e300],
                        [500105.05, 4999800]]]}}]})";
  DemOptions wild = snapped;
  wild.friction_file = hostile;
  wild.friction_snap = 0.25;
  absl::StatusOr<Dem> odd = Dem::Read(path, wild);
  EXPECT_TRUE(odd.ok() || absl::IsInvalidArgument(odd.status())) << odd.status();
  if (odd.ok()) {
    EXPECT_EQ(odd->face_friction().size(), odd->mesh().face_count());
  }

  DemOptions alone;
  alone.friction_snap = 0.1;
  absl::Status s = Dem::Read(path, alone).status();
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  EXPECT_EQ(InvalidOptionOf(s), "friction_snap") << s;
}

}  // namespace
}  // namespace geodex::terrain
