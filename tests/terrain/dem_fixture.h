#pragma once

// The DEM tests' fixture: GeoTIFFs made with GDAL at test time in a temporary directory (a Grid:
// its CRS, corner, cell size and a height function), removed after the test.

#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gdal_priv.h"
#include "gtest/gtest.h"
#include "ogr_spatialref.h"

namespace geodex::terrain {

namespace fs = std::filesystem;

struct Grid {
  int epsg = 32633;
  double x0 = 500000, y0 = 5000000;  // the top-left corner
  double dx = 10, dy = 10;           // pixel size (rows run south)
  int width = 40, height = 30;
  std::function<double(double x, double y, int col, int row)> height_at;
  bool has_nodata = false;
  double nodata = -9999;
  std::string unit;
};

class DemTest : public ::testing::Test {
 protected:
  void SetUp() override {
    GDALAllRegister();
    dir_ = fs::path(::testing::TempDir()) /
           absl::StrCat("geodex-dem-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const Grid& g) {
    const std::string path = (dir_ / name).string();
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
    GDALDataset* ds = driver->Create(path.c_str(), g.width, g.height, 1, GDT_Float64, nullptr);
    double gt[6] = {g.x0, g.dx, 0, g.y0, 0, -g.dy};
    ds->SetGeoTransform(gt);
    OGRSpatialReference srs;
    srs.importFromEPSG(g.epsg);
    ds->SetSpatialRef(&srs);
    GDALRasterBand* band = ds->GetRasterBand(1);
    if (g.has_nodata) band->SetNoDataValue(g.nodata);
    if (!g.unit.empty()) band->SetUnitType(g.unit.c_str());
    std::vector<double> row(g.width);
    for (int j = 0; j < g.height; ++j) {
      for (int i = 0; i < g.width; ++i) {
        row[i] = g.height_at(g.x0 + (i + 0.5) * g.dx, g.y0 - (j + 0.5) * g.dy, i, j);
      }
      EXPECT_EQ(
          band->RasterIO(GF_Write, 0, j, g.width, 1, row.data(), g.width, 1, GDT_Float64, 0, 0),
          CE_None);
    }
    GDALClose(ds);
    return path;
  }

  fs::path dir_;
};

// Flat ground, 30 x 30 cells of 10 m, with a slot of nodata cells in columns 14-15 from row 5 to
// the bottom edge: the shortest path across goes over the slot's top, a taut string.
inline Grid SlotGrid() {
  Grid g;
  g.width = g.height = 30;
  g.has_nodata = true;
  g.height_at = [nodata = g.nodata](double, double, int col, int row) {
    return (col == 14 || col == 15) && row >= 5 ? nodata : 0.0;
  };
  return g;
}

// The straight 3D distance between two points.
inline double Dist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

}  // namespace geodex::terrain
