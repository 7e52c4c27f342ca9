// Friction for travel cost (geodex/friction.h): polygons (GeoJSON text or a file) and rasters give
// each face of a DEM's mesh the value under its centroid; bad files are errors naming the problem.

#include "geodex/friction.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "dem_fixture.h"
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

  // A feature without a friction, or a line, is an error naming it.
  const std::string no_value = R"({"type": "Feature", "properties": {"name": "x"},
    "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 0]]]}})";
  absl::Status s = FrictionFromGeoJson(dem->mesh(), no_value, &dem->info(), "--friction").status();
  EXPECT_NE(s.message().find("no numeric \"friction\""), std::string::npos) << s;
  const std::string line = R"({"type": "Feature", "properties": {"friction": 3},
    "geometry": {"type": "LineString", "coordinates": [[15, 45], [15.1, 45]]}})";
  s = FrictionFromGeoJson(dem->mesh(), line, &dem->info(), "--friction").status();
  EXPECT_NE(s.message().find("friction regions are polygons"), std::string::npos) << s;
  const std::string zero = R"({"type": "Feature", "properties": {"friction": 0},
    "geometry": {"type": "Polygon", "coordinates": [[[15, 45], [15.1, 45], [15, 45.1], [15, 45]]]}})";
  s = FrictionFromGeoJson(dem->mesh(), zero, &dem->info(), "--friction").status();
  EXPECT_NE(s.message().find("friction must be > 0"), std::string::npos) << s;
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

}  // namespace
}  // namespace geodex::terrain
