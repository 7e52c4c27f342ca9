// Rasters aligned with a DEM (geodex/terrain.h): a field's values at the cells (SampleCells: at
// vertices, estimated or solved exactly inside a TIN's faces), and the distance, source and label
// rasters written to a file in the format its extension names, or as GeoTIFF bytes.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "cpl_error.h"
#include "cpl_string.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/distance_matrix.h"
#include "geodex/gis_formats.h"
#include "geodex/point_distance.h"
#include "geodex/terrain.h"
#include "mem_file.h"
#include "ogr_spatialref.h"

namespace geodex::terrain {

absl::StatusOr<CellValues> SampleCells(const Dem& dem, const DistanceField& field,
                                       const TriangleMesh* mesh, const GeodesicOptions* exact) {
  std::optional<TriangleMesh> built;
  if (dem.is_tin() && mesh == nullptr) {
    absl::StatusOr<TriangleMesh> m = TriangleMesh::Build(dem.mesh());
    if (!m.ok()) return m.status();
    mesh = &built.emplace(*std::move(m));
  }
  // A field received from geodexd holds the file vertices' values only: the estimate reads the
  // engine's vertices, each a file vertex's copy with its value.
  std::optional<DistanceField> widened;
  if (dem.is_tin() && field.internal_distance.size() != mesh->vertex_count()) {
    DistanceField& w = widened.emplace();
    w.sources = field.sources;  // a source in the cell's own face is measured straight
    w.internal_distance.resize(mesh->vertex_count());
    w.internal_source.resize(mesh->vertex_count());
    for (uint32_t v = 0; v < mesh->vertex_count(); ++v) {
      w.internal_distance[v] = field.distance[mesh->FileVertex(v)];
      w.internal_source[v] = field.source[mesh->FileVertex(v)];
    }
  }
  const DistanceField& for_estimates = widened ? *widened : field;
  const DemInfo& info = dem.info();
  const size_t cells = size_t{info.grid_width} * info.grid_height;
  if (field.distance.size() < dem.mesh().vertex_count() ||
      field.source.size() < dem.mesh().vertex_count()) {
    return absl::InternalError("one value per vertex expected");
  }
  CellValues out;
  out.travel_time = field.travel_epsilon > 0;
  out.distance.assign(cells, std::numeric_limits<double>::infinity());
  out.source.assign(cells, kNoVertex);
  out.hole.assign(cells, 0);
  std::vector<bool> on_surface(dem.mesh().vertex_count());  // a vertex no face uses: a hole
  for (uint32_t v : dem.mesh().faces) on_surface[v] = true;
  std::vector<SurfacePoint> targets;  // exact: the cells inside faces, solved at once below
  std::vector<size_t> target_cell;
  for (uint32_t row = 0; row < info.grid_height; ++row) {
    for (uint32_t col = 0; col < info.grid_width; ++col) {
      const size_t cell = size_t{row} * info.grid_width + col;
      absl::StatusOr<SurfacePoint> p = dem.CellPoint(col, row);
      if (!p.ok() || (p->kind == SurfacePoint::Kind::kVertex && !on_surface[p->vertex])) {
        out.hole[cell] = 1;
        continue;
      }
      if (p->kind == SurfacePoint::Kind::kVertex) {
        out.distance[cell] = field.distance[p->vertex];
        out.source[cell] = field.source[p->vertex];
        continue;
      }
      if (exact != nullptr) {
        targets.push_back(*p);
        target_cell.push_back(cell);
        continue;
      }
      absl::StatusOr<PointEstimate> e = EstimateDistanceAt(*mesh, for_estimates, *p);
      if (!e.ok()) return e.status();
      out.distance[cell] = e->distance;
      out.source[cell] = e->source;
      out.estimated = true;
    }
  }
  if (!targets.empty()) {
    PointQuery query;
    query.sources = field.sources;
    query.points = std::move(targets);
    query.options = *exact;
    query.covers_surface = true;
    absl::StatusOr<PointValues> values = ComputePointValues(*mesh, query);
    if (!values.ok()) return values.status();
    for (size_t k = 0; k < target_cell.size(); ++k) {
      out.distance[target_cell[k]] = values->distance[k];
      out.source[target_cell[k]] = values->source[k];
    }
    out.exact_stats = values->stats;
  }
  return out;
}

namespace {

// One band on the used grid, made in memory and copied out by the format the path's extension
// names (GisFormatOf); `value_of_cell` gives each cell's value (row-major index), kRasterNoSurface
// (the band's nodata) where there is no surface.
absl::Status WriteRaster(const DemInfo& info, const std::string& path, GDALDataType type,
                         const char* description, const char* unit,
                         const std::function<double(size_t)>& value_of_cell,
                         const Provenance* provenance = nullptr) {
  QuietGdal quiet;
  const GisFormat* format = GisFormatOf(path);
  if (format == nullptr || format->kind != GisFileKind::kRaster) {
    return absl::InvalidArgumentError(absl::StrCat("cannot write ", path, ": a raster is one of ",
                                                   GisExtensions(GisFileKind::kRaster)));
  }
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(format->driver);
  if (mem == nullptr || driver == nullptr ||
      driver->GetMetadataItem(GDAL_DCAP_CREATECOPY) == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot write ", path, ": this GDAL writes no ", format->description));
  }
  auto failed = [&] {
    return absl::PermissionDeniedError(
        absl::StrCat("cannot write ", path, ": ", QuietGdal::LastMessage()));
  };
  GDALDatasetUniquePtr ds(mem->Create("", static_cast<int>(info.grid_width),
                                      static_cast<int>(info.grid_height), 1, type, nullptr));
  if (ds == nullptr) return failed();
  double gt[6];
  std::copy(info.geotransform.begin(), info.geotransform.end(), gt);
  ds->SetGeoTransform(gt);
  OGRSpatialReference crs;
  crs.importFromWkt(info.file_crs_wkt.c_str());
  ds->SetSpatialRef(&crs);
  if (provenance != nullptr) {  // what made the file (gdalinfo lists the items)
    for (const auto& [key, value] : provenance->items) {
      ds->SetMetadataItem(absl::StrCat("GEODEX_", absl::AsciiStrToUpper(key)).c_str(),
                          value.c_str());
      if (key == "software") ds->SetMetadataItem("TIFFTAG_SOFTWARE", value.c_str());
    }
  }
  GDALRasterBand* band = ds->GetRasterBand(1);
  band->SetNoDataValue(kRasterNoSurface);
  band->SetDescription(description);
  if (unit != nullptr) band->SetUnitType(unit);
  std::vector<double> row(info.grid_width);
  for (uint32_t j = 0; j < info.grid_height; ++j) {
    for (uint32_t i = 0; i < info.grid_width; ++i) {
      row[i] = value_of_cell(size_t{j} * info.grid_width + i);
    }
    if (band->RasterIO(GF_Write, 0, static_cast<int>(j), static_cast<int>(info.grid_width), 1,
                       row.data(), static_cast<int>(info.grid_width), 1, GDT_Float64, 0,
                       0) != CE_None) {
      return failed();
    }
  }
  RemoveOldOutput(path);  // CreateCopy will not overwrite
  CPLStringList options;
  if (std::string(format->driver) == "GTiff") {
    options.AddString("COMPRESS=DEFLATE");
    options.AddString("TILED=YES");
  }
  GDALDatasetUniquePtr out(
      driver->CreateCopy(path.c_str(), ds.get(), FALSE, options.List(), nullptr, nullptr));
  if (out == nullptr) return failed();
  out.reset();  // closes the file: a late write error shows in GDAL's last error
  if (CPLGetLastErrorType() >= CE_Failure) return failed();
  return absl::OkStatus();
}

}  // namespace

absl::Status Dem::WriteFloatRaster(const std::string& path,
                                   const std::vector<double>& values) const {
  if (values.size() < mesh_.vertex_count() || is_tin()) {
    return absl::InternalError("one value per vertex of a grid expected (a TIN: SampleCells)");
  }
  std::vector<bool> on_surface(mesh_.vertex_count());  // a vertex no face uses: a hole
  for (uint32_t v : mesh_.faces) on_surface[v] = true;
  return WriteRaster(info_, path, GDT_Float32, "geodesic distance", "m", [&](size_t cell) {
    const uint32_t v = vertex_of_cell_[cell];
    if (v == kNoVertex || !on_surface[v]) return kRasterNoSurface;
    return std::isfinite(values[v]) ? values[v] : kRasterUnreachable;
  });
}

absl::Status Dem::WriteIndexRaster(const std::string& path,
                                   const std::vector<uint32_t>& values) const {
  if (values.size() < mesh_.vertex_count() || is_tin()) {
    return absl::InternalError("one value per vertex of a grid expected (a TIN: SampleCells)");
  }
  std::vector<bool> on_surface(mesh_.vertex_count());
  for (uint32_t v : mesh_.faces) on_surface[v] = true;
  return WriteRaster(info_, path, GDT_Int32, "nearest source", nullptr, [&](size_t cell) {
    const uint32_t v = vertex_of_cell_[cell];
    if (v == kNoVertex || !on_surface[v]) return kRasterNoSurface;
    return values[v] >= 0x80000000u ? kRasterUnreachable : static_cast<double>(values[v]);
  });
}

absl::Status Dem::WriteDistanceRaster(const std::string& path, const CellValues& cells) const {
  if (cells.distance.size() != size_t{info_.grid_width} * info_.grid_height) {
    return absl::InternalError("one value per used cell expected");
  }
  // The band says what its values are: travel time in seconds, or distance in metres.
  const std::string what = cells.travel_time ? "travel time" : "geodesic distance";
  return WriteRaster(
      info_, path, GDT_Float32,
      (cells.estimated ? what + " (section-4 estimate at cell centres)" : what).c_str(),
      cells.travel_time ? "s" : "m",
      [&](size_t cell) {
        if (cells.hole[cell]) return kRasterNoSurface;
        const double d = cells.distance[cell];
        return std::isfinite(d) ? d : kRasterUnreachable;
      },
      &cells.provenance);
}

absl::Status Dem::WriteLabelRaster(const std::string& path, const CellValues& cells) const {
  if (cells.source.size() != size_t{info_.grid_width} * info_.grid_height) {
    return absl::InternalError("one value per used cell expected");
  }
  return WriteRaster(
      info_, path, GDT_Int32, "nearest source", nullptr,
      [&](size_t cell) {
        if (cells.hole[cell]) return kRasterNoSurface;
        const uint32_t s = cells.source[cell];
        return s >= 0x80000000u ? kRasterUnreachable : static_cast<double>(s);
      },
      &cells.provenance);
}

namespace {
// What `write` writes to an in-memory GeoTIFF, as bytes.
absl::StatusOr<std::string> RasterBytes(
    const std::function<absl::Status(const std::string&)>& write) {
  MemFile tiff(".tif");
  if (absl::Status written = write(tiff.path()); !written.ok()) {
    return absl::InternalError(written.message());
  }
  return tiff.Take();
}
}  // namespace

absl::StatusOr<std::string> Dem::FloatRasterBytes(const std::vector<double>& values) const {
  return RasterBytes([&](const std::string& path) { return WriteFloatRaster(path, values); });
}

absl::StatusOr<std::string> Dem::IndexRasterBytes(const std::vector<uint32_t>& values) const {
  return RasterBytes([&](const std::string& path) { return WriteIndexRaster(path, values); });
}

absl::StatusOr<std::string> Dem::DistanceRasterBytes(const CellValues& cells) const {
  return RasterBytes([&](const std::string& path) { return WriteDistanceRaster(path, cells); });
}

absl::StatusOr<std::string> Dem::LabelRasterBytes(const CellValues& cells) const {
  return RasterBytes([&](const std::string& path) { return WriteLabelRaster(path, cells); });
}

}  // namespace geodex::terrain
