#include "geodex/gis_formats.h"

#include <filesystem>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"

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

bool IsOtherGisExtension(const std::string& path) {
  const std::string ext = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  if (ext.size() < 2 || GisFormatOf(path) != nullptr) return false;
  for (const char* plain : {".txt", ".csv", ".json", ".dat", ".out", ".tsv"}) {
    if (ext == plain) return false;  // text the CLI writes itself
  }
  PrepareGdal();
  GDALDriverManager* drivers = GetGDALDriverManager();
  for (int i = 0; i < drivers->GetDriverCount(); ++i) {
    const char* extensions = drivers->GetDriver(i)->GetMetadataItem(GDAL_DMD_EXTENSIONS);
    if (extensions == nullptr) continue;
    for (absl::string_view e : absl::StrSplit(extensions, ' ', absl::SkipEmpty())) {
      if (absl::EqualsIgnoreCase(e, ext.substr(1))) return true;
    }
  }
  return false;
}

void RemoveOldOutput(const std::string& path) {
  // By name, never through a GDAL driver's Delete: that opens the old file with every driver (a
  // file named .tif may be a VRT) and removes whatever it lists.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return;
  std::filesystem::remove(path, ec);
  std::filesystem::path side(path);
  if (absl::EqualsIgnoreCase(side.extension().string(), ".shp")) {
    for (const char* ext : {".shx", ".dbf", ".prj", ".cpg", ".qix", ".sbn", ".sbx"}) {
      std::filesystem::remove(std::filesystem::path(path).replace_extension(ext), ec);
    }
  }
  std::filesystem::remove(path + ".aux.xml", ec);
}

std::string GisExtensions(GisFileKind kind) {
  std::string out;
  for (const GisFormat& f : kFormats) {
    if (f.kind == kind) absl::StrAppend(&out, out.empty() ? "" : ", ", f.extension);
  }
  return out;
}

}  // namespace geodex::terrain
