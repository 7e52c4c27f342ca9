// DEMs as meshes (terrain/include/geodex/terrain.h): fixtures are made at test time with GDAL in a
// temporary directory; answers are analytic (geodesics on a plane are straight lines, and around a
// polygonal hole they are taut strings through its corners).

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "dem_fixture.h"
#include "gdal_priv.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geojson.h"
#include "geodex/gis_formats.h"
#include "geodex/terrain.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"
#include "util/test_meshes.h"

namespace geodex::terrain {
namespace {

namespace fs = std::filesystem;

// The tilted plane z = 0.1 (x - 500000) + 0.2 (y - 4999700).
double Plane(double x, double y) { return 0.1 * (x - 500000) + 0.2 * (y - 4999700); }

DemOptions Step(uint32_t step) {
  DemOptions options;
  options.step = step;
  return options;
}

TEST_F(DemTest, ProjectedPlaneIsItsOwnGridAndGeodesicsAreStraight) {
  Grid g;
  g.height_at = [](double x, double y, int, int) { return Plane(x, y); };
  absl::StatusOr<Dem> dem = Dem::Read(Write("plane.tif", g));
  ASSERT_TRUE(dem.ok()) << dem.status();
  const DemInfo& info = dem->info();
  EXPECT_EQ(info.grid_width, 40u);
  EXPECT_EQ(info.grid_height, 30u);
  EXPECT_EQ(info.nodata_cells, 0u);
  EXPECT_FALSE(info.reprojected);
  EXPECT_NE(info.file_crs_name.find("UTM zone 33N"), std::string::npos) << info.file_crs_name;
  EXPECT_EQ(dem->mesh().vertex_count(), 40u * 30u);
  EXPECT_EQ(dem->mesh().face_count(), 2u * 39u * 29u);
  // Vertex (i, j) sits at the cell centre, at the cell's height.
  const uint32_t v = dem->VertexAt(7, 11);
  EXPECT_DOUBLE_EQ(dem->mesh().positions[3 * v], 500075);
  EXPECT_DOUBLE_EQ(dem->mesh().positions[3 * v + 1], 5000000 - 115);
  EXPECT_DOUBLE_EQ(dem->mesh().positions[3 * v + 2], Plane(500075, 4999885));

  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(mesh->report().flipped_faces, 0u);  // every face wound the same way
  // Map points (not on vertices) dropped vertically: on the plane, at their x and y.
  const std::vector<std::array<double, 2>> xy = {
      {500013.3, 4999981.7}, {500301.9, 4999722.2}, {500390, 4999900}, {500150.5, 4999850.5}};
  std::vector<SurfacePoint> points;
  for (const auto& [x, y] : xy) {
    absl::StatusOr<SurfacePoint> p = dem->DropMapPoint(x, y);
    ASSERT_TRUE(p.ok()) << p.status();
    const std::array<double, 3> at = PositionOf(dem->mesh(), *p);
    EXPECT_NEAR(at[0], x, 1e-8);
    EXPECT_NEAR(at[1], y, 1e-8);
    EXPECT_NEAR(at[2], Plane(x, y), 1e-8);
    points.push_back(*p);
  }
  absl::StatusOr<std::vector<std::pair<double, uint32_t>>> d =
      ComputeExactDistancesAt(*mesh, {points[0]}, points);
  ASSERT_TRUE(d.ok()) << d.status();
  for (size_t k = 0; k < points.size(); ++k) {
    const std::array<double, 3> a = {xy[0][0], xy[0][1], Plane(xy[0][0], xy[0][1])};
    const std::array<double, 3> b = {xy[k][0], xy[k][1], Plane(xy[k][0], xy[k][1])};
    EXPECT_NEAR((*d)[k].first, Dist(a, b), 1e-9 * 500) << k;
  }
}

// The same plane on a longitude/latitude grid: the mesh is in the UTM zone of the centre (33N),
// where each cell centre is given the plane's height at its UTM position, so the surface is that
// plane again and distances are the straight-line ones, in metres.
TEST_F(DemTest, GeographicGridIsProjectedToUtmInMetres) {
  OGRSpatialReference wgs84, utm;
  wgs84.importFromEPSG(4326);
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  utm.importFromEPSG(32633);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformation* to_utm = OGRCreateCoordinateTransformation(&wgs84, &utm);
  ASSERT_NE(to_utm, nullptr);
  auto utm_of = [&](double lon, double lat) {
    double x = lon, y = lat;
    EXPECT_TRUE(to_utm->Transform(1, &x, &y));
    return std::array<double, 2>{x, y};
  };
  Grid g;
  g.epsg = 4326;
  g.x0 = 14.99;
  g.y0 = 45.16;
  g.dx = g.dy = 0.0002;  // about 16 by 22 m
  g.width = 40;
  g.height = 35;
  g.height_at = [&](double lon, double lat, int, int) {
    const auto [x, y] = utm_of(lon, lat);
    return Plane(x, y);
  };
  absl::StatusOr<Dem> dem = Dem::Read(Write("geo.tif", g));
  ASSERT_TRUE(dem.ok()) << dem.status();
  EXPECT_TRUE(dem->info().reprojected);
  EXPECT_NE(dem->info().mesh_crs_name.find("UTM zone 33N"), std::string::npos)
      << dem->info().mesh_crs_name;
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
  ASSERT_TRUE(mesh.ok());
  const std::vector<std::array<double, 2>> ll = {
      {14.99131, 45.15873}, {14.99711, 45.15412}, {14.9977, 45.1581}, {14.9912, 45.1538}};
  std::vector<SurfacePoint> points;
  std::vector<std::array<double, 3>> expected;
  for (const auto& [lon, lat] : ll) {
    absl::StatusOr<SurfacePoint> p = dem->DropLonLat(lon, lat);
    ASSERT_TRUE(p.ok()) << p.status();
    points.push_back(*p);
    const auto [x, y] = utm_of(lon, lat);
    expected.push_back({x, y, Plane(x, y)});
    const std::array<double, 3> at = PositionOf(dem->mesh(), *p);
    EXPECT_NEAR(at[0], x, 1e-6);
    EXPECT_NEAR(at[1], y, 1e-6);
  }
  OGRCoordinateTransformation::DestroyCT(to_utm);
  absl::StatusOr<std::vector<std::pair<double, uint32_t>>> d =
      ComputeExactDistancesAt(*mesh, {points[0]}, points);
  ASSERT_TRUE(d.ok()) << d.status();
  for (size_t k = 1; k < points.size(); ++k) {
    const double want = Dist(expected[0], expected[k]);
    EXPECT_GT(want, 300);
    // The cell centres lie on the plane exactly; the surface between them is that plane.
    EXPECT_NEAR((*d)[k].first, want, 1e-6) << k;
  }
}

// A slot of nodata cells (columns 14-15, rows 5 to the bottom edge) on flat ground: the shortest
// path from one side to the other goes over the slot's top, a taut string through its corners.
TEST_F(DemTest, NodataHoleIsGoneAround) {
  const Grid g = SlotGrid();
  absl::StatusOr<Dem> dem = Dem::Read(Write("slot.tif", g));
  ASSERT_TRUE(dem.ok()) << dem.status();
  EXPECT_EQ(dem->info().nodata_cells, 2u * 25u);
  EXPECT_EQ(dem->VertexAt(14, 5), kNoVertex);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
  ASSERT_TRUE(mesh.ok());
  auto centre = [&](double col, double row) {
    return std::array<double, 3>{g.x0 + (col + 0.5) * g.dx, g.y0 - (row + 0.5) * g.dy, 0};
  };
  const std::array<double, 3> a = centre(10, 15), b = centre(20, 15);
  absl::StatusOr<SurfacePoint> pa = dem->DropMapPoint(a[0], a[1]);
  absl::StatusOr<SurfacePoint> pb = dem->DropMapPoint(b[0], b[1]);
  ASSERT_TRUE(pa.ok() && pb.ok());
  absl::StatusOr<std::vector<std::pair<double, uint32_t>>> d =
      ComputeExactDistancesAt(*mesh, {*pa}, {*pb});
  ASSERT_TRUE(d.ok()) << d.status();
  // Over the top: the left edge's top (13, 4), the top edge to (15, 4), and the cut corner (16, 5)
  // (block (15, 4) keeps its triangle (15,4)-(16,5)-(16,4)).
  const double want = Dist(a, centre(13, 4)) + Dist(centre(13, 4), centre(15, 4)) +
                      Dist(centre(15, 4), centre(16, 5)) + Dist(centre(16, 5), b);
  EXPECT_NEAR((*d)[0].first, want, 1e-9 * want);
  EXPECT_GT((*d)[0].first, 2.5 * Dist(a, b));
  // The cell centres on the slot's edges are vertices of the surface: they drop (a point on a grid
  // line is in two blocks, one of them the hole's).
  for (double col : {13.0, 16.0}) {
    const std::array<double, 3> edge = centre(col, 12);
    absl::StatusOr<SurfacePoint> p = dem->DropMapPoint(edge[0], edge[1]);
    ASSERT_TRUE(p.ok()) << col << ": " << p.status();
    const std::array<double, 3> at = PositionOf(dem->mesh(), *p);
    EXPECT_NEAR(at[0], edge[0], 1e-9);
    EXPECT_NEAR(at[1], edge[1], 1e-9);
  }
  // A point in the slot, and one outside the grid, are errors naming them.
  absl::StatusOr<SurfacePoint> in_hole =
      dem->DropMapPoint(centre(14.5, 20)[0], centre(14.5, 20)[1]);
  EXPECT_EQ(in_hole.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(in_hole.status().message().find("in a hole of the DEM"), std::string::npos)
      << in_hole.status();
  absl::StatusOr<SurfacePoint> outside = dem->DropMapPoint(g.x0 - 1, g.y0 - 100);
  EXPECT_NE(outside.status().message().find("outside the DEM"), std::string::npos)
      << outside.status();
  EXPECT_NE(outside.status().message().find("g:499999:"), std::string::npos) << outside.status();
}

// The same slot as sea (cells at -5 m) with a barrier below 0: the same detour, and the mesh file
// rule (a face with a corner below the barrier is removed) agrees with the DEM's.
TEST_F(DemTest, BarrierBelowIsGoneAroundLikeNodata) {
  Grid g;
  g.width = g.height = 30;
  g.height_at = [&](double, double, int col, int row) {
    return (col == 14 || col == 15) && row >= 5 ? -5.0 : 1.0;
  };
  const std::string path = Write("sea.tif", g);
  DemOptions options;
  options.barrier_below = 0;
  absl::StatusOr<Dem> dem = Dem::Read(path, options);
  ASSERT_TRUE(dem.ok()) << dem.status();
  EXPECT_EQ(dem->info().barrier_cells, 50u);
  EXPECT_EQ(dem->info().nodata_cells, 0u);
  auto centre = [&](double col, double row) {
    return std::array<double, 3>{g.x0 + (col + 0.5) * g.dx, g.y0 - (row + 0.5) * g.dy, 1};
  };
  const std::array<double, 3> a = centre(10, 15), b = centre(20, 15);
  const double want = Dist(a, centre(13, 4)) + Dist(centre(13, 4), centre(15, 4)) +
                      Dist(centre(15, 4), centre(16, 5)) + Dist(centre(16, 5), b);
  absl::StatusOr<Dem> open = Dem::Read(path);  // no barrier: the sea is crossed
  ASSERT_TRUE(open.ok());
  const MeshData file_rule = RemoveFacesBelow(open->mesh(), 0);
  EXPECT_EQ(file_rule.face_count(), dem->mesh().face_count());
  for (const MeshData* data : {&dem->mesh(), &file_rule}) {
    absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
    ASSERT_TRUE(mesh.ok());
    // The same map points on either mesh (faces keep their order among the kept ones).
    absl::StatusOr<SurfacePoint> pa = dem->DropMapPoint(a[0], a[1]);
    absl::StatusOr<SurfacePoint> pb = dem->DropMapPoint(b[0], b[1]);
    ASSERT_TRUE(pa.ok() && pb.ok());
    if (data == &file_rule) {  // vertex ids differ (the sea's vertices stay, isolated)
      pa = open->DropMapPoint(a[0], a[1]);
      pb = open->DropMapPoint(b[0], b[1]);
      ASSERT_TRUE(pa.ok() && pb.ok());
      // Faces are renumbered by the removal: find the kept face holding the same corners.
      for (SurfacePoint* p : {&*pa, &*pb}) {
        const uint32_t* corners = &open->mesh().faces[3 * size_t{p->face}];
        for (size_t f = 0; f < file_rule.face_count(); ++f) {
          if (std::equal(corners, corners + 3, &file_rule.faces[3 * f]))
            p->face = static_cast<uint32_t>(f);
        }
      }
    }
    absl::StatusOr<std::vector<std::pair<double, uint32_t>>> d =
        ComputeExactDistancesAt(*mesh, {*pa}, {*pb});
    ASSERT_TRUE(d.ok()) << d.status();
    EXPECT_NEAR((*d)[0].first, want, 1e-9 * want);
  }
}

TEST_F(DemTest, RastersOutAreAlignedWithTheGridAndMarkNodata) {
  Grid g;
  g.width = 21;
  g.height = 17;
  g.has_nodata = true;
  g.height_at = [&](double x, double y, int col, int row) {
    return col == 5 && row == 6 ? g.nodata : Plane(x, y);
  };
  for (uint32_t step : {1u, 2u}) {
    absl::StatusOr<Dem> dem = Dem::Read(Write("out.tif", g), Step(step));
    ASSERT_TRUE(dem.ok()) << dem.status();
    std::vector<double> values(dem->mesh().vertex_count());
    std::vector<uint32_t> labels(values.size());
    for (size_t v = 0; v < values.size(); ++v) {
      values[v] = dem->mesh().positions[3 * v] - 500000;  // the cell centre's x, offset
      labels[v] = v % 3 == 0 ? 0xffffffffu : static_cast<uint32_t>(v % 5);
    }
    values[1] = std::numeric_limits<double>::infinity();  // unreachable
    const std::string dist = (dir_ / "d.tif").string(), lab = (dir_ / "l.tif").string();
    ASSERT_TRUE(dem->WriteFloatRaster(dist, values).ok());
    ASSERT_TRUE(dem->WriteIndexRaster(lab, labels).ok());
    GDALDataset* ds = static_cast<GDALDataset*>(GDALOpen(dist.c_str(), GA_ReadOnly));
    ASSERT_NE(ds, nullptr);
    EXPECT_EQ(ds->GetRasterXSize(), static_cast<int>(dem->info().grid_width));
    EXPECT_EQ(ds->GetRasterYSize(), static_cast<int>(dem->info().grid_height));
    EXPECT_EQ(ds->GetRasterBand(1)->GetRasterDataType(), GDT_Float32);
    double gt[6];
    ASSERT_EQ(ds->GetGeoTransform(gt), CE_None);
    for (int k = 0; k < 6; ++k) EXPECT_DOUBLE_EQ(gt[k], dem->info().geotransform[k]) << k;
    const OGRSpatialReference file_crs(dem->info().file_crs_wkt.c_str());
    EXPECT_TRUE(ds->GetSpatialRef() != nullptr && ds->GetSpatialRef()->IsSame(&file_crs));
    std::vector<double> read(size_t{dem->info().grid_width} * dem->info().grid_height);
    ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(
                  GF_Read, 0, 0, dem->info().grid_width, dem->info().grid_height, read.data(),
                  dem->info().grid_width, dem->info().grid_height, GDT_Float64, 0, 0),
              CE_None);
    GDALClose(ds);
    for (uint32_t j = 0; j < dem->info().grid_height; ++j) {
      for (uint32_t i = 0; i < dem->info().grid_width; ++i) {
        const uint32_t v = dem->VertexAt(i, j);
        const double got = read[size_t{j} * dem->info().grid_width + i];
        // The pixel's centre, by the output's own geotransform, is the vertex's x.
        const double centre_x = gt[0] + (i + 0.5) * gt[1] - 500000;
        if (v == kNoVertex) {
          EXPECT_EQ(got, kRasterNoSurface) << i << "," << j;  // no surface: nodata
        } else if (v == 1) {
          EXPECT_EQ(got, kRasterUnreachable) << i << "," << j;  // on the surface, unreachable
        } else {
          EXPECT_NEAR(got, centre_x, 1e-3) << i << "," << j;
        }
      }
    }
    if (step == 1) {
      EXPECT_EQ(dem->VertexAt(5, 6), kNoVertex);
    }
    GDALDataset* ls = static_cast<GDALDataset*>(GDALOpen(lab.c_str(), GA_ReadOnly));
    ASSERT_NE(ls, nullptr);
    EXPECT_EQ(ls->GetRasterBand(1)->GetRasterDataType(), GDT_Int32);
    int32_t first = 0;
    ASSERT_EQ(ls->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 1, 1, &first, 1, 1, GDT_Int32, 0, 0),
              CE_None);
    EXPECT_EQ(first, kRasterUnreachable);  // vertex 0: no label (unreachable)
    GDALClose(ls);
  }
}

// A CRS in US survey feet (NAD83 / California zone 3, EPSG:2227): the mesh is in metres, in that
// CRS's frame, and map points are given in feet.
TEST_F(DemTest, FootBasedCrsGivesAMeshInMetres) {
  Grid g;
  g.epsg = 2227;
  g.x0 = 6000000;
  g.y0 = 2100000;
  g.dx = g.dy = 100;  // feet
  g.width = 10;
  g.height = 8;
  g.height_at = [](double, double, int, int) { return 5.0; };
  absl::StatusOr<Dem> dem = Dem::Read(Write("feet_crs.tif", g));
  ASSERT_TRUE(dem.ok()) << dem.status();
  const double foot = 1200.0 / 3937.0;
  EXPECT_NEAR(dem->info().horizontal_scale, foot, 1e-12);
  EXPECT_NE(dem->info().mesh_crs_name.find("in metres"), std::string::npos);
  const uint32_t v = dem->VertexAt(3, 2);
  EXPECT_NEAR(dem->mesh().positions[3 * v], (6000000 + 350) * foot, 1e-6);
  EXPECT_NEAR(dem->mesh().positions[3 * v + 1], (2100000 - 250) * foot, 1e-6);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
  ASSERT_TRUE(mesh.ok());
  absl::StatusOr<SurfacePoint> a = dem->DropMapPoint(6000120, 2099880);
  absl::StatusOr<SurfacePoint> b = dem->DropMapPoint(6000720, 2099280);
  ASSERT_TRUE(a.ok() && b.ok());
  absl::StatusOr<std::vector<std::pair<double, uint32_t>>> d =
      ComputeExactDistancesAt(*mesh, {*a}, {*b});
  ASSERT_TRUE(d.ok());
  EXPECT_NEAR((*d)[0].first, std::hypot(600, 600) * foot, 1e-6);  // flat: straight, in metres
}

TEST_F(DemTest, BadRastersAreClearErrors) {
  Grid g;
  g.height_at = [](double, double, int, int) { return 1.0; };
  const std::string ok = Write("ok.tif", g);
  // No CRS.
  {
    const std::string path = (dir_ / "nocrs.tif").string();
    GDALDataset* ds = GetGDALDriverManager()->GetDriverByName("GTiff")->Create(
        path.c_str(), 4, 4, 1, GDT_Float32, nullptr);
    double gt[6] = {0, 1, 0, 0, 0, -1};
    ds->SetGeoTransform(gt);
    GDALClose(ds);
    absl::StatusOr<Dem> dem = Dem::Read(path);
    EXPECT_EQ(dem.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(dem.status().message().find("no coordinate reference system"), std::string::npos)
        << dem.status();
  }
  // Not a raster, missing, too coarse a step, an unknown height unit.
  std::ofstream(dir_ / "junk.tif") << "not a tiff";
  EXPECT_EQ(Dem::Read((dir_ / "junk.tif").string()).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(Dem::Read((dir_ / "missing.tif").string()).status().code(),
            absl::StatusCode::kNotFound);
  absl::StatusOr<Dem> coarse = Dem::Read(ok, Step(40));
  EXPECT_NE(coarse.status().message().find("at least 2x2"), std::string::npos) << coarse.status();
  g.unit = "furlong";
  absl::StatusOr<Dem> odd = Dem::Read(Write("odd.tif", g));
  EXPECT_NE(odd.status().message().find("furlong"), std::string::npos) << odd.status();
  // Feet are converted to metres.
  g.unit = "ft";
  absl::StatusOr<Dem> feet = Dem::Read(Write("feet.tif", g));
  ASSERT_TRUE(feet.ok()) << feet.status();
  EXPECT_DOUBLE_EQ(feet->mesh().positions[2], 0.3048);
  // A geographic grid whose centre is not on the Earth (found by tests/fuzz/dem_fuzzer: a UTM
  // zone computed from 1e20 degrees overflowed; such cells are now refused as too small, and a
  // centre at 1000 degrees as not on the Earth).
  Grid off_earth = g;
  off_earth.unit.clear();
  off_earth.epsg = 4326;
  off_earth.x0 = 1000;
  off_earth.y0 = 45;
  off_earth.dx = off_earth.dy = 0.001;
  absl::StatusOr<Dem> far = Dem::Read(Write("far.tif", off_earth));
  EXPECT_EQ(far.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(far.status().message().find("not a longitude (within [-360, 360]) and latitude"),
            std::string::npos)
      << far.status();
}

}  // namespace
}  // namespace geodex::terrain

namespace geodex::terrain {
namespace {

// The isochrone's fast union (exact tiling: unshared edges chained into rings) gives the same
// valid area as GEOS's general union, also where lobes touch at a point: a checkerboard field
// below its mid level is diamonds around every other vertex, touching diagonally.
TEST_F(DemTest, TiledUnionEqualsTheGeneralUnionWithTouchingLobes) {
  Grid g;
  g.width = 12;
  g.height = 9;
  g.height_at = [](double, double, int, int) { return 0.0; };
  absl::StatusOr<Dem> dem = Dem::Read(Write("flat.tif", g));
  ASSERT_TRUE(dem.ok()) << dem.status();
  std::vector<double> value(dem->mesh().vertex_count());
  for (uint32_t j = 0; j < 9; ++j) {
    for (uint32_t i = 0; i < 12; ++i) value[dem->VertexAt(i, j)] = (i + j) % 2 == 0 ? 0 : 10;
  }
  value[dem->VertexAt(11, 8)] = std::numeric_limits<double>::infinity();  // unreachable corner
  auto area_of = [&](bool tiled, const std::string& name) {
    GeoFeature f;
    f.kind = GeoFeature::Kind::kArea;
    f.pieces = SublevelPieces(dem->mesh(), value, 5);
    f.exact_tiling = tiled;
    const std::string path = (dir_ / name).string();
    EXPECT_TRUE(WriteVectorFile(dem->info(), {f}, path, /*native_crs=*/true).ok());
    GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
    EXPECT_NE(ds, nullptr);
    OGRFeatureUniquePtr feature(ds->GetLayer(0)->GetNextFeature());
    return std::unique_ptr<OGRGeometry>(feature->StealGeometry());
  };
  std::unique_ptr<OGRGeometry> tiled = area_of(true, "tiled.geojson");
  std::unique_ptr<OGRGeometry> general = area_of(false, "general.geojson");
  ASSERT_TRUE(tiled != nullptr && general != nullptr);
  EXPECT_TRUE(tiled->IsValid());
  EXPECT_TRUE(general->IsValid());
  const double area =
      tiled->toMultiPolygon() != nullptr && wkbFlatten(tiled->getGeometryType()) == wkbMultiPolygon
          ? tiled->toMultiPolygon()->get_Area()
          : tiled->toPolygon()->get_Area();
  EXPECT_GT(area, 1000);
  std::unique_ptr<OGRGeometry> difference(tiled->SymDifference(general.get()));
  ASSERT_NE(difference, nullptr);
  const double diff = wkbFlatten(difference->getGeometryType()) == wkbMultiPolygon
                          ? difference->toMultiPolygon()->get_Area()
                      : wkbFlatten(difference->getGeometryType()) == wkbPolygon
                          ? difference->toPolygon()->get_Area()
                          : 0.0;
  EXPECT_LT(diff, 1e-9 * area);
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Every map point of `points` drops onto the same face point from `a` and `b`.
void ExpectSameDrops(const Dem& a, const Dem& b, const std::vector<std::array<double, 2>>& points) {
  for (const auto& [x, y] : points) {
    absl::StatusOr<SurfacePoint> pa = a.DropMapPoint(x, y), pb = b.DropMapPoint(x, y);
    ASSERT_EQ(pa.ok(), pb.ok()) << x << " " << y << ": " << pa.status() << " / " << pb.status();
    if (!pa.ok()) {
      EXPECT_EQ(pa.status().message(), pb.status().message());
      continue;
    }
    EXPECT_EQ(pa->face, pb->face) << x << " " << y;
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(pa->bary[c], pb->bary[c]) << x << " " << y;
  }
}

// geodexd reads uploaded GeoTIFF bytes (GTiff only) into the same mesh the file gives, and rebuilds
// a stored DEM from its mesh and info: the same vertices, faces and dropped points.
TEST_F(DemTest, BytesAndStoredMeshGiveTheSameDem) {
  Grid g;
  g.width = g.height = 30;
  g.has_nodata = true;
  g.height_at = [&](double x, double y, int col, int row) {
    return (col == 14 || col == 15) && row >= 5 ? g.nodata : Plane(x, y);
  };
  const std::string path = Write("slot.tif", g);
  DemOptions options;
  options.step = 2;
  absl::StatusOr<Dem> file = Dem::Read(path, options);
  ASSERT_TRUE(file.ok()) << file.status();
  absl::StatusOr<Dem> bytes = Dem::ReadGeoTiffBytes(Slurp(path), "upload.tif", options);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  EXPECT_EQ(bytes->mesh().positions, file->mesh().positions);
  EXPECT_EQ(bytes->mesh().faces, file->mesh().faces);
  EXPECT_EQ(bytes->info().file_crs_wkt, file->info().file_crs_wkt);
  EXPECT_EQ(bytes->info().geotransform, file->info().geotransform);

  std::vector<std::array<double, 2>> points;
  for (double u = -1.3; u < 32; u += 0.77) {
    for (double v = 0.2; v < 31; v += 1.9) points.push_back({g.x0 + u * g.dx, g.y0 - v * g.dy});
  }
  absl::StatusOr<Dem> stored = Dem::FromMesh(file->mesh(), file->info());
  ASSERT_TRUE(stored.ok()) << stored.status();
  ExpectSameDrops(*file, *stored, points);
  for (uint32_t j = 0; j < file->info().grid_height; ++j) {
    for (uint32_t i = 0; i < file->info().grid_width; ++i) {
      ASSERT_EQ(stored->VertexAt(i, j), file->VertexAt(i, j)) << i << " " << j;
    }
  }
  // A mesh that is not this DEM's is refused: vertices out of row order, a face across blocks.
  MeshData swapped = file->mesh();
  std::swap_ranges(swapped.positions.begin(), swapped.positions.begin() + 3,
                   swapped.positions.begin() + 3);
  EXPECT_EQ(Dem::FromMesh(swapped, file->info()).status().code(),
            absl::StatusCode::kInvalidArgument);
  MeshData stretched = file->mesh();
  stretched.faces[2] = stretched.faces[2] + 5;
  absl::Status across = Dem::FromMesh(stretched, file->info()).status();
  EXPECT_NE(across.message().find("not one of a block's two triangles"), std::string::npos)
      << across;

  // Bad bytes are clear errors, and the cell limit holds before any row is read.
  EXPECT_NE(Dem::ReadGeoTiffBytes("solid\nfacet", "x.tif").status().message().find("not a GeoTIFF"),
            std::string::npos);
  std::string cut = Slurp(path);
  cut.resize(cut.size() / 3);
  EXPECT_EQ(Dem::ReadGeoTiffBytes(cut, "cut.tif").status().code(),
            absl::StatusCode::kInvalidArgument);
  DemOptions small;
  small.max_cells = 899;
  EXPECT_EQ(Dem::ReadGeoTiffBytes(Slurp(path), "big.tif", small).status().code(),
            absl::StatusCode::kResourceExhausted);
  small.max_cells = 900;
  EXPECT_TRUE(Dem::ReadGeoTiffBytes(Slurp(path), "big.tif", small).ok());
}

// An upload whose geographic CRS carries EPSG:4342, a geocentric CRS's code (found by dem_fuzzer:
// PROJ 9.1 dereferenced null building a transformation from it, or a bound CRS for the check of
// PROJ text naming files), is refused with the code named, by both readers, before PROJ sees it.
TEST_F(DemTest, ACrsWithAnotherKindsCodeIsRefusedNotACrash) {
  const std::string path = TestDataPath("bad_bound_crs.tif");
  const std::string bytes = Slurp(path);
  ASSERT_GT(bytes.size(), 100u) << path;
  for (const absl::StatusOr<Dem>& dem :
       {Dem::ReadGeoTiffBytes(bytes, "upload.tif"), Dem::Read(path)}) {
    ASSERT_FALSE(dem.ok());
    EXPECT_EQ(dem.status().code(), absl::StatusCode::kInvalidArgument) << dem.status();
    EXPECT_NE(
        dem.status().message().find("geographic CRS carries the code EPSG:4342, a geocentric"),
        std::string::npos)
        << dem.status();
  }
}

// The same for a geographic grid (the mesh in UTM): cells are found by projecting back.
// Another datum (WGS 72, shifted to WGS 84's UTM): PROJ's 2D round trip is off by ~1e-10
// degrees, a millionth of these cells, yet a stored DEM still finds every vertex's cell (found by
// dem_fuzzer: "vertex 0 is not at a cell centre" after a geodexd restart). And a grid that counts
// longitudes 0 to 360 (common in climate and ocean data): PROJ brings points back in [-180, 180],
// a turn away from its cells, yet its stored DEM finds them too, and ll: points (always in
// [-180, 180]) land where its own longitudes do (found by dem_fuzzer).
class StoredDatumTest : public DemTest,
                        public ::testing::WithParamInterface<std::pair<int, double>> {};

TEST_P(StoredDatumTest, StoredGeographicMeshGivesTheSameDem) {
  Grid g;
  g.epsg = GetParam().first;
  g.x0 = GetParam().second;
  g.y0 = 45.16;
  g.dx = g.dy = 0.0002;
  g.width = 25;
  g.height = 20;
  g.height_at = [&](double lon, double lat, int, int) {
    return 1000 * (lon - g.x0) + 300 * (lat - 45);
  };
  absl::StatusOr<Dem> file = Dem::Read(Write("geo.tif", g));
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_TRUE(file->info().reprojected);
  absl::StatusOr<Dem> stored = Dem::FromMesh(file->mesh(), file->info());
  ASSERT_TRUE(stored.ok()) << stored.status();
  std::vector<std::array<double, 2>> points;
  for (double u = 0.1; u < 25; u += 1.37) {
    for (double v = 0.3; v < 21; v += 2.1) points.push_back({g.x0 + u * g.dx, g.y0 - v * g.dy});
  }
  ExpectSameDrops(*file, *stored, points);
  if (g.x0 < 180) return;
  for (const Dem* dem : {&*file, &*stored}) {
    for (const auto& [x, y] : points) {
      absl::StatusOr<SurfacePoint> map = dem->DropMapPoint(x, y), ll = dem->DropLonLat(x - 360, y);
      ASSERT_EQ(map.ok(), ll.ok()) << x << " " << y << ": " << map.status() << " / " << ll.status();
      if (!map.ok()) continue;
      const std::array<double, 3> a = PositionOf(dem->mesh(), *map),
                                  b = PositionOf(dem->mesh(), *ll);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6) << x << " " << y;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Datums, StoredDatumTest,
                         ::testing::Values(std::pair{4326, 14.99}, std::pair{4322, 14.99},
                                           std::pair{4267, 14.99}, std::pair{4326, 189.99}));

// A longitude/latitude grid is at most a turn wide and stays within the poles; its centre alone
// (which PROJ wraps) let a grid of cells 858,225 degrees wide through, whose stored mesh could not
// find its cells again (dem_fuzzer, tests/fuzz/corpus/dem/dem-stored-round-trip).
TEST_F(DemTest, LongitudeLatitudeGridPastATurnOrAPoleIsRefused) {
  Grid wide;
  wide.epsg = 4326;
  wide.x0 = 10;
  wide.y0 = 40;
  wide.dx = 20;
  wide.dy = 0.001;
  wide.width = 25;
  wide.height = 20;
  wide.height_at = [](double, double, int, int) { return 1.0; };
  Grid polar = wide;
  polar.dx = 0.001;
  polar.y0 = 90.5;
  polar.dy = 0.1;
  for (const auto& [g, name, what] :
       {std::tuple{wide, "wide.tif", "grid 500 degrees wide"},
        std::tuple{polar, "polar.tif", "rows from latitude 88.5 to 90.5"}}) {
    absl::StatusOr<Dem> dem = Dem::Read(Write(name, g));
    ASSERT_FALSE(dem.ok()) << name;
    EXPECT_EQ(dem.status().code(), absl::StatusCode::kInvalidArgument) << dem.status();
    EXPECT_NE(dem.status().message().find(what), std::string::npos) << dem.status();
  }
}

// Found by dem_fuzzer (CI, 2026-11-28; again on 2026-11-29): a geographic CRS whose prime meridian
// is 1.1e119 degrees east read, but every longitude lost its digits to the meridian, the cells
// fell on one line and the stored mesh did not come back (Dem::FromMesh: "vertex 0 is not at a
// cell centre"). It is refused, naming the meridian.
TEST_F(DemTest, AGeographicCrsWithAFarPrimeMeridianIsRefused) {
  const std::string path = TestDataPath("far_prime_meridian.tif");
  absl::StatusOr<Dem> dem = Dem::Read(path);
  ASSERT_FALSE(dem.ok());
  EXPECT_EQ(dem.status().code(), absl::StatusCode::kInvalidArgument) << dem.status();
  EXPECT_NE(dem.status().message().find("prime meridian"), std::string::npos) << dem.status();
}

}  // namespace
}  // namespace geodex::terrain
