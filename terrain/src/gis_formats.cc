#include "geodex/gis_formats.h"

#include <filesystem>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/travel_cost.h"

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

Provenance MakeProvenance(const std::string& made_by, const GeodesicOptions* options) {
  Provenance out;
  out.items.push_back({"software", "geodex " GEODEX_VERSION});
  if (!made_by.empty()) out.items.push_back({"made_by", made_by});
  if (options == nullptr) return out;
  const bool travel = options->travel.has_value();
  out.items.push_back({"values", travel ? "travel time" : "geodesic distance"});
  out.items.push_back({"units", travel ? "s" : "m"});
  if (travel) {
    const TravelCost& t = *options->travel;
    out.items.push_back({"speed", t.speed_model == SpeedModel::kConstant
                                      ? absl::StrFormat("constant %g km/h", t.speed_kmh)
                                      : std::string(SpeedModelName(t.speed_model))});
    const bool exact = TravelIsExact(t);
    out.items.push_back({"exact", exact ? "true" : "false"});
    out.items.push_back({"epsilon", absl::StrFormat("%g", StatedTravelEpsilon(t))});
    // Within (1 + epsilon) of the least time: proved at a constant speed, not for slope speeds.
    out.items.push_back({"bound", exact || !IsDirectional(t) ? "true" : "false"});
    if (t.face_weight != nullptr) out.items.push_back({"friction", "per face"});
    if (t.max_slope_deg > 0 && t.max_slope_deg < 90) {
      out.items.push_back({"max_slope_deg", absl::StrFormat("%g", t.max_slope_deg)});
    }
  } else {
    out.items.push_back({"exact", options->lambda > 0 ? "false" : "true"});
    if (options->lambda > 0)
      out.items.push_back({"lambda", absl::StrFormat("%g", options->lambda)});
  }
  return out;
}

std::string JsonQuoted(const std::string& text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      out += absl::StrFormat("\\u%04x", c);
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string ProvenanceJson(const Provenance& provenance) {
  std::string out = "{";
  for (size_t i = 0; i < provenance.items.size(); ++i) {
    absl::StrAppend(&out, i ? ", " : "", JsonQuoted(provenance.items[i].first), ": ",
                    JsonQuoted(provenance.items[i].second));
  }
  return out + "}";
}

}  // namespace geodex::terrain
