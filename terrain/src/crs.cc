// CRS handling for the DEM readers (dem_internal.h): texts of coordinates and CRSs,
// transformations (PROJ's network off), the EPSG codes a file's CRS claims checked, a reprojected
// DEM's file CRS to its mesh CRS and back, longitudes brought to a grid's side, and a DEM's file
// CRS parsed.

#include <charconv>
#include <cmath>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "cpl_conv.h"
#include "cpl_string.h"
#include "dem_internal.h"
#include "gdal_quiet.h"
#include "geodex/terrain.h"
#include "ogr_spatialref.h"

namespace geodex::terrain::dem_internal {

// The shortest text that reads back as `value` (500301.9, not 500301.90000000002): how a person
// writes the coordinates that messages quote.
std::string Shortest(double value) {
  char text[400];
  const double a = std::abs(value);
  const auto end =
      (a == 0 || (a >= 1e-4 && a < 1e15))
          ? std::to_chars(text, text + sizeof(text), value, std::chars_format::fixed).ptr
          : std::to_chars(text, text + sizeof(text), value).ptr;
  return std::string(text, end);
}

std::string WktOf(const OGRSpatialReference& srs) {
  char* wkt = nullptr;
  srs.exportToWkt(&wkt);
  std::string out = wkt != nullptr ? wkt : "";
  CPLFree(wkt);
  return out;
}

TransformPtr MakeTransform(const OGRSpatialReference& from, const OGRSpatialReference& to) {
  PrepareGdal();  // PROJ's network off before any transformation is made
  return TransformPtr(OGRCreateCoordinateTransformation(&from, &to),
                      &OGRCoordinateTransformation::DestroyCT);
}

// A CRS that carries an EPSG code must be the kind of CRS PROJ knows under that code: PROJ 9.1
// looks the code up when it builds a transformation, and dereferences null when a file's geographic
// CRS says it is EPSG:4342, a geocentric CRS (found by dem_fuzzer; tests/data/bad_bound_crs.tif).
// The CRS itself and, for a projected CRS, its base are checked. "" when it is consistent.
std::string InconsistentCrsId(const OGRSpatialReference& srs) {
  auto kind = [](const OGRSpatialReference& crs) -> std::string {
    if (crs.IsCompound()) return "compound";
    if (crs.IsProjected()) return "projected";
    if (crs.IsGeocentric()) return "geocentric";
    if (crs.IsGeographic()) return "geographic";
    if (crs.IsLocal()) return "engineering";
    return "other";
  };
  for (const char* node : {static_cast<const char*>(nullptr), "GEOGCS"}) {
    const char* authority = srs.GetAuthorityName(node);
    const char* code = srs.GetAuthorityCode(node);
    if (authority == nullptr || code == nullptr || !EQUAL(authority, "EPSG")) continue;
    int number = 0;
    if (!absl::SimpleAtoi(code, &number) || number <= 0) {
      return absl::StrCat("its CRS carries the code EPSG:", std::string(code).substr(0, 20),
                          ", which is not a number");
    }
    OGRSpatialReference known;
    if (known.importFromEPSG(number) != OGRERR_NONE) {
      return absl::StrCat("its CRS carries the code EPSG:", number, ", which PROJ does not know");
    }
    const std::string claimed =
        node == nullptr ? kind(srs) : (srs.IsProjected() ? "geographic" : kind(srs));
    if (kind(known) != claimed) {
      return absl::StrCat("its ", claimed, " CRS carries the code EPSG:", number, ", a ",
                          kind(known), " CRS");
    }
  }
  return "";
}

// A reprojected DEM's file CRS to its mesh CRS (the UTM zone), or back; null when either CRS does
// not parse or PROJ has no transformation.
TransformPtr FileMeshTransform(const DemInfo& info, bool to_mesh) {
  OGRSpatialReference file_crs, mesh_crs;
  if (file_crs.importFromWkt(info.file_crs_wkt.c_str()) != OGRERR_NONE ||
      mesh_crs.importFromWkt(info.mesh_crs_wkt.c_str()) != OGRERR_NONE) {
    return TransformPtr(nullptr, &OGRCoordinateTransformation::DestroyCT);
  }
  file_crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  mesh_crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  // Back is the forward operation inverted, never a second search: between datums (WGS 72 to
  // WGS 84's UTM) PROJ may pick another operation each way, and a stored DEM's vertices would not
  // land back on its cell centres (found by dem_fuzzer).
  TransformPtr forward = MakeTransform(file_crs, mesh_crs);
  if (to_mesh || forward == nullptr) return forward;
  return TransformPtr(forward->GetInverse(), &OGRCoordinateTransformation::DestroyCT);
}

// Degrees per angular unit of a geographic CRS given as WKT; 0 when it does not parse or is not
// geographic.
double DegreesPerUnit(const std::string& wkt) {
  OGRSpatialReference crs;
  if (crs.importFromWkt(wkt.c_str()) != OGRERR_NONE || !crs.IsGeographic()) return 0;
  const double radians = crs.GetAngularUnits();
  return std::isfinite(radians) && radians > 0 ? radians * 180 / M_PI : 0;
}

// Longitudes brought back into a longitude/latitude file's CRS (from UTM, WGS 84), moved by whole
// turns to the grid's side: PROJ answers in [-180, 180], and a file may count 0 to 360 (found by
// dem_fuzzer: a stored mesh whose vertices came back a turn away from their cells).
void LongitudesToGrid(const DemInfo& info, double* xs, size_t n) {
  const double degrees = info.reprojected ? DegreesPerUnit(info.file_crs_wkt) : 0;
  if (degrees == 0) return;
  const double turn = 360 / degrees;
  const double centre = info.geotransform[0] + info.geotransform[1] * info.grid_width / 2;
  for (size_t k = 0; k < n; ++k) {
    if (std::isfinite(xs[k])) xs[k] -= turn * std::round((xs[k] - centre) / turn);
  }
}

// The DEM's file CRS in x-y order into *crs (left empty without a DEM); InvalidArgument starting
// with `name` when its text does not parse.
absl::Status ParseFileCrs(const DemInfo* dem, const std::string& name, OGRSpatialReference* crs) {
  if (dem == nullptr) return absl::OkStatus();
  if (crs->importFromWkt(dem->file_crs_wkt.c_str()) != OGRERR_NONE) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": the DEM's CRS does not parse"));
  }
  crs->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return absl::OkStatus();
}

}  // namespace geodex::terrain::dem_internal
