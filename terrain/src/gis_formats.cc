#include "geodex/gis_formats.h"

#include <filesystem>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"

namespace geodex::terrain {
namespace {

constexpr GisFormat kFormats[] = {
    {".tif", "GTiff", GisFileKind::kRaster, "GeoTIFF"},
    {".tiff", "GTiff", GisFileKind::kRaster, "GeoTIFF"},
    {".asc", "AAIGrid", GisFileKind::kRaster, "Esri ASCII grid"},
    {".nc", "netCDF", GisFileKind::kRaster, "netCDF"},
    {".geojson", "GeoJSON", GisFileKind::kVector, "GeoJSON (RFC 7946)"},
    {".gpkg", "GPKG", GisFileKind::kVector, "GeoPackage"},
    {".shp", "ESRI Shapefile", GisFileKind::kVector, "Shapefile"},
    {".fgb", "FlatGeobuf", GisFileKind::kVector, "FlatGeobuf"},
};

}  // namespace

const GisFormat* GisFormatOf(const std::string& path) {
  const std::string ext = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  for (const GisFormat& f : kFormats) {
    if (ext == f.extension) return &f;
  }
  return nullptr;
}

std::string GisExtensions(GisFileKind kind) {
  std::string out;
  for (const GisFormat& f : kFormats) {
    if (f.kind == kind) absl::StrAppend(&out, out.empty() ? "" : ", ", f.extension);
  }
  return out;
}

}  // namespace geodex::terrain
