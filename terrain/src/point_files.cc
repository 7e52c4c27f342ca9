// Point files (geodex/terrain.h's ReadPointsFile, FilePointSpec): the points of a CSV, GeoJSON or
// other vector file with their CRS, and a point's SPEC (g:X:Y without a CRS, else ll:LON:LAT).

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "dem_internal.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/terrain.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"

namespace geodex::terrain {

using dem_internal::MakeTransform;
using dem_internal::OpenBarrierFile;
using dem_internal::Shortest;
using dem_internal::TransformPtr;
using dem_internal::WktOf;

absl::StatusOr<std::vector<FilePoint>> ReadPointsFile(const std::string& path,
                                                      const std::string& name) {
  QuietGdal quiet;
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(name, ": cannot open: ", std::strerror(errno)));
  char first = ' ';
  while (in.get(first) && absl::ascii_isspace(static_cast<unsigned char>(first))) {
  }
  const std::string ext = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  const bool csv = ext == ".csv";
  GDALDatasetUniquePtr ds;
  if (csv) {
    // x,y columns (the DEM's CRS), or lon,lat / longitude,latitude (WGS 84).
    const char* const drivers[] = {"CSV", nullptr};
    const char* const options[] = {"X_POSSIBLE_NAMES=x,lon,longitude,lng",
                                   "Y_POSSIBLE_NAMES=y,lat,latitude", "KEEP_GEOM_COLUMNS=NO",
                                   nullptr};
    const char* const no_siblings[] = {nullptr};
    ds.reset(GDALDataset::FromHandle(GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY,
                                                drivers, options, no_siblings)));
    if (ds == nullptr)
      return bad(absl::StrCat("not a CSV file with x,y or lon,lat columns (",
                              QuietGdal::LastMessage(), ")"));
  } else {
    absl::StatusOr<GDALDatasetUniquePtr> file = OpenBarrierFile(path, name);
    if (!file.ok()) return file.status();
    ds = *std::move(file);
  }
  std::vector<FilePoint> points;
  OGRSpatialReference wgs84;
  wgs84.SetWellKnownGeogCS("WGS84");
  for (OGRLayer* layer : ds->GetLayers()) {
    const OGRSpatialReference* layer_crs = layer->GetSpatialRef();
    std::string wkt;
    if (layer_crs != nullptr) {
      wkt = WktOf(*layer_crs);
    } else if (csv) {
      // KEEP_GEOM_COLUMNS=NO drops the coordinate columns: the header says which they were.
      std::ifstream header(path);
      std::string line;
      std::getline(header, line);
      bool lonlat = false;
      for (absl::string_view cell : absl::StrSplit(absl::AsciiStrToLower(line), ',')) {
        cell = absl::StripAsciiWhitespace(cell);
        lonlat |= cell == "lon" || cell == "longitude" || cell == "lng";
      }
      if (lonlat) wkt = WktOf(wgs84);
    } else if (first == '{') {  // GeoJSON without a crs: RFC 7946's WGS 84
      wkt = WktOf(wgs84);
    }
    for (const auto& feature : *layer) {
      const OGRGeometry* g = feature->GetGeometryRef();
      if (g == nullptr) continue;
      const std::string feature_name = absl::StrCat(name, " feature ", feature->GetFID());
      auto add = [&](const OGRPoint* p) {
        points.push_back({p->getX(), p->getY(), wkt, feature_name});
      };
      switch (wkbFlatten(g->getGeometryType())) {
        case wkbPoint:
          add(g->toPoint());
          break;
        case wkbMultiPoint:
          for (const OGRPoint* p : *g->toMultiPoint()) add(p);
          break;
        default:
          return bad(absl::StrCat("feature ", feature->GetFID(), " is a ", g->getGeometryName(),
                                  "; points are expected"));
      }
    }
  }
  if (points.empty()) return bad("no point");
  return points;
}

absl::StatusOr<std::string> FilePointSpec(const FilePoint& point) {
  if (point.crs_wkt.empty()) return absl::StrCat("g:", Shortest(point.x), ":", Shortest(point.y));
  QuietGdal quiet;
  OGRSpatialReference from, wgs84;
  if (from.importFromWkt(point.crs_wkt.c_str()) != OGRERR_NONE)
    return absl::InvalidArgumentError("its CRS does not parse");
  from.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  TransformPtr t = MakeTransform(from, wgs84);
  double x = point.x, y = point.y;
  if (t == nullptr || !t->Transform(1, &x, &y)) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot project it to WGS 84 (", QuietGdal::LastMessage(), ")"));
  }
  return absl::StrCat("ll:", Shortest(x), ":", Shortest(y));
}

}  // namespace geodex::terrain
