#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "barrier_cut.h"
#include "cpl_conv.h"
#include "cpl_error.h"
#include "cpl_json.h"
#include "cpl_string.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/adaptive_tin.h"
#include "geodex/distance_matrix.h"
#include "geodex/friction.h"
#include "geodex/gis_formats.h"
#include "geodex/limits.h"
#include "geodex/point_distance.h"
#include "geodex/terrain.h"
#include "mem_file.h"
#include "ogr_api.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"

namespace geodex::terrain {
namespace {

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

using TransformPtr =
    std::unique_ptr<OGRCoordinateTransformation, decltype(&OGRCoordinateTransformation::DestroyCT)>;
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

// Metres per unit of a band's height unit; 0 when the unit is not one geodex knows.
double MetresPerHeightUnit(std::string unit) {
  unit = absl::AsciiStrToLower(unit);
  if (unit.empty() || unit == "m" || unit == "metre" || unit == "meter" || unit == "metres" ||
      unit == "meters") {
    return 1;
  }
  if (unit == "ft" || unit == "foot" || unit == "feet" || unit == "international foot")
    return 0.3048;
  if (unit == "us survey foot" || unit == "us-ft" || unit == "ftus") return 1200.0 / 3937.0;
  return 0;
}

// The transform from a vector layer's CRS (WGS 84 when it names none, as GeoJSON's default) to
// `crs`; null when `crs` is null (the features stay as they are). Errors start with `name`.
absl::StatusOr<TransformPtr> LayerToCrs(OGRLayer& layer, const OGRSpatialReference* crs,
                                        const std::string& name) {
  TransformPtr out(nullptr, &OGRCoordinateTransformation::DestroyCT);
  if (crs == nullptr) return out;
  OGRSpatialReference from;
  if (const OGRSpatialReference* layer_crs = layer.GetSpatialRef(); layer_crs != nullptr) {
    from = *layer_crs;
  } else {
    from.SetWellKnownGeogCS("WGS84");
  }
  from.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  out = MakeTransform(from, *crs);
  if (out == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": cannot project it to the DEM's CRS (",
                                                   QuietGdal::LastMessage(), ")"));
  }
  return out;
}

// Every polygon, line and point of a vector dataset, in `crs` (null: as they are, no CRS), as one
// collection (a cut buffers the lines and points and unions everything). Errors start with `name`.
absl::StatusOr<std::unique_ptr<OGRGeometry>> BarrierPolygonsOf(GDALDataset* ds,
                                                               const std::string& name,
                                                               const OGRSpatialReference* crs) {
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
  };
  if (ds == nullptr)
    return bad(absl::StrCat("not a vector file GDAL reads (", QuietGdal::LastMessage(), ")"));
  auto all = std::make_unique<OGRGeometryCollection>();
  for (OGRLayer* layer : ds->GetLayers()) {
    absl::StatusOr<TransformPtr> to_dem = LayerToCrs(*layer, crs, name);
    if (!to_dem.ok()) return to_dem.status();
    for (const auto& feature : *layer) {
      const OGRGeometry* g = feature->GetGeometryRef();
      if (g == nullptr) continue;
      std::unique_ptr<OGRGeometry> copy(g->clone());
      if (*to_dem != nullptr && copy->transform(to_dem->get()) != OGRERR_NONE) {
        return bad(absl::StrCat("cannot project a feature to the DEM's CRS (",
                                QuietGdal::LastMessage(), ")"));
      }
      switch (wkbFlatten(copy->getGeometryType())) {
        case wkbPolygon:
        case wkbMultiPolygon:
        case wkbLineString:
        case wkbMultiLineString:
        case wkbPoint:
        case wkbMultiPoint:
          all->addGeometryDirectly(copy.release());
          break;
        default:
          return bad(absl::StrCat("feature ", feature->GetFID(), " is a ", copy->getGeometryName(),
                                  "; a barrier is polygons, lines or points"));
      }
    }
  }
  if (all->IsEmpty()) return bad("no polygon, line or point");
  return std::unique_ptr<OGRGeometry>(std::move(all));
}

// One friction polygon (or multipolygon) with its value.
struct FrictionRegion {
  std::unique_ptr<OGRGeometry> shape;
  double friction;
};

// Coordinates beyond this (in any unit a file may use) are a mistake, not a map: refused rather
// than left to GEOS, where they overflow (a friction polygon at 1e308 once vanished in silence).
constexpr double kMaxMapCoordinate = 1e12;

// Why a friction polygon cannot be used as drawn ("" when it can): a coordinate not finite or
// absurd, a ring with fewer than 3 distinct points; an invalid polygon is repaired as the cut
// repairs it (areas kept, collapsed parts dropped) and refused when no area is left.
std::string UnusableFrictionShape(std::unique_ptr<OGRGeometry>* shape) {
  std::string why;
  std::function<void(const OGRGeometry&)> check = [&](const OGRGeometry& g) {
    if (!why.empty()) return;
    if (const auto* collection = dynamic_cast<const OGRGeometryCollection*>(&g)) {
      for (const OGRGeometry* part : *collection) check(*part);
      return;
    }
    const auto* polygon = dynamic_cast<const OGRPolygon*>(&g);
    if (polygon == nullptr) return;
    for (const OGRLinearRing* ring : *polygon) {
      std::set<std::pair<double, double>> distinct;
      for (const OGRPoint& p : *ring) {
        const double x = p.getX(), y = p.getY();
        if (!std::isfinite(x) || !std::isfinite(y)) {
          why = "a coordinate is not a finite number";
          return;
        }
        if (std::abs(x) > kMaxMapCoordinate || std::abs(y) > kMaxMapCoordinate) {
          why = absl::StrFormat("a coordinate (%g, %g) is beyond %g in size", x, y,
                                kMaxMapCoordinate);
          return;
        }
        distinct.insert({x, y});
      }
      if (distinct.size() < 3) {
        why = absl::StrFormat("a ring has %d distinct points; a polygon's ring needs 3 or more",
                              distinct.size());
        return;
      }
    }
  };
  check(**shape);
  if (!why.empty() || (*shape)->IsValid()) return why;
  std::unique_ptr<OGRGeometry> valid((*shape)->MakeValid());
  auto polygons = std::make_unique<OGRMultiPolygon>();
  std::function<void(const OGRGeometry&)> keep = [&](const OGRGeometry& g) {
    if (const auto* collection = dynamic_cast<const OGRGeometryCollection*>(&g)) {
      for (const OGRGeometry* part : *collection) keep(*part);
    } else if (dynamic_cast<const OGRPolygon*>(&g) != nullptr) {
      polygons->addGeometry(&g);
    }
  };
  if (valid != nullptr) keep(*valid);
  if (polygons->IsEmpty() || polygons->get_Area() <= 0) {
    return "the polygon is invalid and encloses no area once repaired";
  }
  *shape = std::move(polygons);
  return "";
}

// The friction polygons of a vector dataset, checked (polygons only, each with a numeric
// "friction" > 0) and projected to `crs` (null: as they are). Both uses start here: the faces'
// values (FaceFrictionOf) and the outlines cut into a mesh (OutlinesOf).
absl::StatusOr<std::vector<FrictionRegion>> ReadFrictionRegions(GDALDataset& ds,
                                                                const OGRSpatialReference* crs,
                                                                const std::string& name) {
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
  };
  std::vector<FrictionRegion> regions;
  for (OGRLayer* layer : ds.GetLayers()) {
    absl::StatusOr<TransformPtr> to_dem = LayerToCrs(*layer, crs, name);
    if (!to_dem.ok()) return to_dem.status();
    const int field = layer->GetLayerDefn()->GetFieldIndex("friction");
    const OGRFieldType type =
        field >= 0 ? layer->GetLayerDefn()->GetFieldDefn(field)->GetType() : OFTString;
    for (const auto& feature : *layer) {
      const std::string which = absl::StrCat("feature ", feature->GetFID());
      if (field < 0 || !feature->IsFieldSetAndNotNull(field) ||
          (type != OFTReal && type != OFTInteger && type != OFTInteger64)) {
        return bad(absl::StrCat(which, " has no numeric \"friction\" property"));
      }
      const double friction = feature->GetFieldAsDouble(field);
      if (!(friction > 0)) {
        return bad(absl::StrCat(which, ": friction must be > 0, got ", friction));
      }
      const OGRGeometry* g = feature->GetGeometryRef();
      if (g == nullptr) return bad(absl::StrCat(which, " has no geometry"));
      const OGRwkbGeometryType kind = wkbFlatten(g->getGeometryType());
      if (kind != wkbPolygon && kind != wkbMultiPolygon) {
        return bad(
            absl::StrCat(which, " is a ", g->getGeometryName(), "; friction regions are polygons"));
      }
      std::unique_ptr<OGRGeometry> copy(g->clone());
      if (std::string why = UnusableFrictionShape(&copy); !why.empty()) {
        return bad(absl::StrCat(which, ": ", why));
      }
      if (*to_dem != nullptr && copy->transform(to_dem->get()) != OGRERR_NONE) {
        return bad(absl::StrCat("cannot project ", which, " to the DEM's CRS (",
                                QuietGdal::LastMessage(), ")"));
      }
      regions.push_back({std::move(copy), friction});
    }
  }
  if (regions.empty()) return bad("no friction polygon");
  return regions;
}

// Each face's friction under its centre: `regions` in the map (the DEM's CRS) with `dem`, in the
// mesh's own x y without (defined below, with the readers).
absl::StatusOr<std::vector<double>> FaceFrictionOf(std::vector<FrictionRegion> regions,
                                                   const MeshData& mesh, const DemInfo* dem,
                                                   const std::string& name);

// The regions' shapes as one collection: what CutOutlines splits the mesh along.
std::unique_ptr<OGRGeometry> OutlinesOf(const std::vector<FrictionRegion>& regions) {
  auto all = std::make_unique<OGRGeometryCollection>();
  for (const FrictionRegion& r : regions) all->addGeometry(r.shape.get());
  return all;
}

// Two collections of BarrierPolygonsOf as one (the second's members moved into the first).
std::unique_ptr<OGRGeometry> JoinCollections(std::unique_ptr<OGRGeometry> a,
                                             std::unique_ptr<OGRGeometry> b) {
  auto* into = a->toGeometryCollection();
  auto* from = b->toGeometryCollection();
  while (!from->IsEmpty()) {
    into->addGeometryDirectly(from->getGeometryRef(0)->clone());
    from->removeGeometry(0);
  }
  return a;
}

// Several files of one flag as messages name them together: "--friction a.geojson, --friction
// b.gpkg".
std::string FlagFilesName(absl::string_view flag, const std::vector<std::string>& paths) {
  return absl::StrJoin(paths, ", ", [&](std::string* out, const std::string& path) {
    absl::StrAppend(out, "--", flag, " ", path);
  });
}

}  // namespace

std::string BarrierFilesName(const std::vector<std::string>& paths) {
  return FlagFilesName("barrier", paths);
}

absl::Status CheckFrictionSnap(double friction_snap, bool has_outlines) {
  if (!(friction_snap >= 0 && friction_snap <= 0.25)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--friction-snap: must be in [0, 0.25] (a fraction of the shortest edge at a "
                     "vertex; 0: exact), got ",
                     friction_snap));
  }
  if (friction_snap > 0 && !has_outlines) {
    return absl::InvalidArgumentError(
        "--friction-snap: snaps friction outlines cut into the mesh (--friction-boundaries exact "
        "with friction polygons); there are none");
  }
  return absl::OkStatus();
}

Dem::Dem(Dem&&) noexcept = default;
Dem& Dem::operator=(Dem&&) noexcept = default;
Dem::~Dem() = default;

MeshData RemoveFacesBelow(const MeshData& mesh, double z) {
  MeshData out;
  out.positions = mesh.positions;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    bool keep = true;
    for (int c = 0; c < 3; ++c) {
      const size_t v = mesh.faces[3 * f + c];
      // An out-of-range corner is kept for TriangleMesh::Build to report.
      keep &= !(v < mesh.vertex_count() && mesh.positions[3 * v + 2] < z);
    }
    if (keep) out.faces.insert(out.faces.end(), &mesh.faces[3 * f], &mesh.faces[3 * f] + 3);
  }
  return out;
}

bool IsDemPath(const std::string& path) {
  std::string ext = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  for (const char* known :
       {".tif", ".tiff", ".vrt", ".asc", ".img", ".hgt", ".dem", ".bil", ".nc"}) {
    if (ext == known) return true;
  }
  return false;
}

namespace {

// A CRS named in GeoJSON by an identifier PROJ resolves from its own database (EPSG:32633,
// urn:ogc:def:crs:EPSG::32633, OGC:CRS84): no path, no URL.
bool IsCrsIdentifier(const std::string& name) {
  if (name.empty() || name.size() > 128 || name.find(':') == std::string::npos) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return absl::ascii_isalnum(static_cast<unsigned char>(c)) || c == ':' || c == '_' || c == '.' ||
           c == '-';
  });
}

// GDAL's GeoJSON driver follows a "crs" member of type "link" or "url" (an HTTP request to
// wherever it names), on the collection and on any geometry, and resolves a "name" with PROJ.
// Every "crs" member, at any depth (GDAL matches member names in any case), must name its CRS by an
// identifier (type "name") or an EPSG code (type "EPSG"); anything else is refused before GDAL
// sees the text. PrepareGdal's refusing fetcher stays the backstop.
absl::Status CheckGeoJsonCrs(const CPLJSONObject& node, const std::string& where) {
  if (node.GetType() == CPLJSONObject::Type::Array) {
    const CPLJSONArray items = node.ToArray();
    for (int i = 0; i < items.Size(); ++i) {
      if (absl::Status s = CheckGeoJsonCrs(items[i], where); !s.ok()) return s;
    }
    return absl::OkStatus();
  }
  if (node.GetType() != CPLJSONObject::Type::Object) return absl::OkStatus();
  for (const CPLJSONObject& member : node.GetChildren()) {
    if (!absl::EqualsIgnoreCase(member.GetName(), "crs")) {
      if (absl::Status s = CheckGeoJsonCrs(member, where); !s.ok()) return s;
      continue;
    }
    auto refuse = [&](const std::string& why) {
      return absl::InvalidArgumentError(absl::StrCat(
          where, ": ", why, "; geodex reads no URL or file that its input names: give the CRS as ",
          R"({"type": "name", "properties": {"name": "EPSG:32633"}})"));
    };
    if (member.GetType() == CPLJSONObject::Type::Null) continue;
    if (member.GetType() != CPLJSONObject::Type::Object)
      return refuse("its \"crs\" is not an object");
    // GDAL reads the first member of a name in any case; this check would read another: refuse
    // names that differ only in case ("name" and "NAME").
    auto repeats = [](const CPLJSONObject& object) {
      std::set<std::string> seen;
      for (const CPLJSONObject& field : object.GetChildren()) {
        if (!seen.insert(absl::AsciiStrToLower(field.GetName())).second) return true;
      }
      return false;
    };
    bool repeated = repeats(member);
    for (const CPLJSONObject& field : member.GetChildren()) {
      if (field.GetType() == CPLJSONObject::Type::Object) repeated |= repeats(field);
    }
    if (repeated) return refuse("its \"crs\" repeats a member (names differing only in case)");
    std::string type;
    CPLJSONObject properties;
    for (const CPLJSONObject& field : member.GetChildren()) {
      if (absl::EqualsIgnoreCase(field.GetName(), "type")) type = field.ToString();
      if (absl::EqualsIgnoreCase(field.GetName(), "properties")) properties = field;
    }
    std::string value;
    bool integer_code = false;
    if (properties.GetType() == CPLJSONObject::Type::Object) {
      for (const CPLJSONObject& field : properties.GetChildren()) {
        if (absl::EqualsIgnoreCase(field.GetName(), "name")) value = field.ToString();
        if (absl::EqualsIgnoreCase(field.GetName(), "code")) {
          integer_code = field.GetType() == CPLJSONObject::Type::Integer ||
                         field.GetType() == CPLJSONObject::Type::Long;
        }
      }
    }
    if (absl::EqualsIgnoreCase(type, "name")) {
      if (!IsCrsIdentifier(value)) {
        return refuse(absl::StrCat("its \"crs\" name \"", value.substr(0, 80),
                                   "\" is not a CRS identifier such as EPSG:32633"));
      }
    } else if (!(absl::EqualsIgnoreCase(type, "EPSG") && integer_code)) {
      return refuse(
          absl::StrCat("its \"crs\" of type \"", type.substr(0, 40), "\" is not followed"));
    }
  }
  return absl::OkStatus();
}

// The files beside a local file whose names start with its stem (.prj, .hdr, .shx, .dbf,
// .aux.xml): its side-cars, given to GDAL by name since PrepareGdal stops it listing directories.
CPLStringList SideCarsOf(const std::string& path) {
  CPLStringList siblings;
  const std::filesystem::path file(path);
  const std::string stem = absl::AsciiStrToLower(file.stem().string());
  std::error_code ec;
  std::filesystem::directory_iterator dir(file.has_parent_path() ? file.parent_path() : ".", ec),
      end;
  for (int seen = 0; !ec && dir != end && seen < 10000; dir.increment(ec), ++seen) {
    const std::string sibling = dir->path().filename().string();
    if (absl::StartsWith(absl::AsciiStrToLower(sibling), stem)) siblings.AddString(sibling.c_str());
  }
  return siblings;
}

// A user's own raster file (a DEM or a friction raster), through the drivers of the formats
// IsDemPath names, with its side-cars given by name. Not VRT: its sources name files and URLs of
// their own, opened by any driver. Null when none of the drivers reads it (QuietGdal's message).
GDALDatasetUniquePtr OpenUserRaster(const std::string& path) {
  const char* const drivers[] = {"GTiff",   "AAIGrid", "HFA",    "SRTMHGT",
                                 "USGSDEM", "EHdr",    "netCDF", nullptr};
  CPLStringList siblings = SideCarsOf(path);
  return GDALDatasetUniquePtr(GDALDataset::FromHandle(GDALOpenEx(
      path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, drivers, nullptr, siblings.List())));
}

// A barrier file the CLI's user names: GeoJSON (its "crs" checked as for text), a Shapefile,
// GeoPackage or FlatGeobuf, each through its own driver only (no KML network links, GML schemas
// or VRT sources).
absl::StatusOr<GDALDatasetUniquePtr> OpenBarrierFile(const std::string& path,
                                                     const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(name, ": cannot open: ", std::strerror(errno)));
  char first = ' ';
  while (in.get(first) && absl::ascii_isspace(static_cast<unsigned char>(first))) {
  }
  if (first == '{') {
    in.seekg(0);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CPLJSONDocument document;
    if (!document.LoadMemory(text)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": not GeoJSON (", QuietGdal::LastMessage(), ")"));
    }
    if (absl::Status crs = CheckGeoJsonCrs(document.GetRoot(), name); !crs.ok()) return crs;
  }
  const char* const geojson[] = {"GeoJSON", nullptr};
  const char* const others[] = {"ESRI Shapefile", "GPKG", "FlatGeobuf", nullptr};
  CPLStringList siblings = SideCarsOf(path);
  GDALDatasetUniquePtr ds(GDALDataset::FromHandle(
      GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, first == '{' ? geojson : others,
                 nullptr, siblings.List())));
  if (ds == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": not a GeoJSON, Shapefile, GeoPackage or FlatGeobuf file (",
                     QuietGdal::LastMessage(), ")"));
  }
  return ds;
}

}  // namespace

namespace {

// Polygons in the DEM file's CRS (`file_crs`) brought to the mesh's frame: into the mesh's CRS
// when the DEM was reprojected (their edges then straight there, as the cutter draws them), else
// left in the file's units with *scale the mesh's metres per unit. No `dem`: the mesh's own x y.
absl::Status PolygonsToMeshFrame(OGRGeometry& polygons, const DemInfo* dem,
                                 const OGRSpatialReference* file_crs, const std::string& name,
                                 double* scale) {
  *scale = 1;
  if (dem != nullptr && dem->reprojected) {
    OGRSpatialReference mesh_crs;
    if (mesh_crs.importFromWkt(dem->mesh_crs_wkt.c_str()) != OGRERR_NONE) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": the DEM's mesh CRS does not parse"));
    }
    mesh_crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    TransformPtr to_mesh = MakeTransform(*file_crs, mesh_crs);
    if (to_mesh == nullptr || polygons.transform(to_mesh.get()) != OGRERR_NONE) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": the polygons do not project to the mesh's CRS (",
                       QuietGdal::LastMessage(), ")"));
    }
  } else if (dem != nullptr) {
    *scale = dem->horizontal_scale;
  }
  return absl::OkStatus();
}

absl::StatusOr<MeshData> CutBarrier(const MeshData& mesh, OGRGeometry& polygons, const DemInfo* dem,
                                    const OGRSpatialReference* file_crs, double width,
                                    uint64_t max_vertices, const std::string& name,
                                    CutStats* stats) {
  double scale = 1;
  if (absl::Status s = PolygonsToMeshFrame(polygons, dem, file_crs, name, &scale); !s.ok())
    return s;
  absl::StatusOr<MeshData> cut = CutOutPolygons(mesh, polygons, scale, width, max_vertices, stats);
  if (absl::IsInvalidArgument(cut.status())) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", cut.status().message()));
  }
  return cut;
}

// Friction regions' outlines cut into the mesh (SplitAlongOutlines), polygons as CutBarrier's.
absl::StatusOr<MeshData> CutOutlines(const MeshData& mesh, OGRGeometry& polygons,
                                     const DemInfo* dem, const OGRSpatialReference* file_crs,
                                     uint64_t max_vertices, const std::string& name,
                                     CutStats* stats) {
  double scale = 1;
  if (absl::Status s = PolygonsToMeshFrame(polygons, dem, file_crs, name, &scale); !s.ok())
    return s;
  absl::StatusOr<MeshData> cut = SplitAlongOutlines(mesh, polygons, scale, max_vertices, stats);
  if (absl::IsInvalidArgument(cut.status())) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", cut.status().message()));
  }
  return cut;
}

// Every ring of the polygons in `g` (a polygon, a multipolygon or a collection of them).
void ForEachRing(OGRGeometry& g, const std::function<void(OGRLinearRing&)>& visit) {
  if (auto* polygon = dynamic_cast<OGRPolygon*>(&g)) {
    for (OGRLinearRing* ring : *polygon) visit(*ring);
  } else if (auto* collection = dynamic_cast<OGRGeometryCollection*>(&g)) {
    for (OGRGeometry* part : *collection) ForEachRing(*part, visit);
  }
}

// Friction regions in the mesh's own x y (projected to its CRS, or scaled to metres): there a
// snapped outline point is a vertex's very coordinates, and the cut (scale 1) and the faces'
// values (centres in mesh x y) read the same shapes.
absl::Status RegionsToMeshFrame(std::vector<FrictionRegion>& regions, const DemInfo& dem,
                                const OGRSpatialReference& file_crs, const std::string& name) {
  for (FrictionRegion& region : regions) {
    double scale = 1;
    if (absl::Status s = PolygonsToMeshFrame(*region.shape, &dem, &file_crs, name, &scale);
        !s.ok()) {
      return s;
    }
    if (scale == 1) continue;
    ForEachRing(*region.shape, [scale](OGRLinearRing& ring) {
      for (int i = 0; i < ring.getNumPoints(); ++i) {
        ring.setPoint(i, ring.getX(i) * scale, ring.getY(i) * scale);
      }
    });
  }
  return absl::OkStatus();
}

// DemOptions::friction_snap: outlines (in the mesh's x y) moved onto the vertices they pass
// within `fraction` x the vertex's shortest x-y edge of. Why: an outline crossing an edge that
// close to its end leaves pieces with a tiny angle (the crossing is shared with the neighbouring
// face, which must take it as a corner), and the bounded engine's Steiner points per edge grow as
// 1 / sin(smallest angle), its links per face as their square. Through the vertex, the outline
// leaves no such piece there. A region whose snapped outline is no longer a valid polygon (two
// of its stretches closer than the discs) keeps its drawn shape.
void SnapOutlinesToVertices(std::vector<FrictionRegion>& regions, const MeshData& mesh,
                            double fraction) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const size_t n = mesh.vertex_count();
  auto xy = [&](uint32_t v) {
    return std::array<double, 2>{mesh.positions[3 * size_t{v}], mesh.positions[3 * size_t{v} + 1]};
  };
  std::vector<double> radius(n, kInf);  // (kInf until an edge is seen; 0 below: no face uses it)
  std::vector<double> lengths;
  lengths.reserve(mesh.faces.size());
  for (size_t c = 0; c < mesh.faces.size(); ++c) {
    const uint32_t a = mesh.faces[c], b = mesh.faces[c - c % 3 + (c + 1) % 3];
    const double length = std::hypot(xy(a)[0] - xy(b)[0], xy(a)[1] - xy(b)[1]);
    radius[a] = std::min(radius[a], fraction * length);
    radius[b] = std::min(radius[b], fraction * length);
    lengths.push_back(length);
  }
  if (lengths.empty()) return;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  const double cell = lengths[lengths.size() / 2];
  if (!(cell > 0)) return;
  // A disc reaches at most 4 buckets away: a vertex with only long edges (an adaptive TIN's flat
  // expanse) snaps less rather than fill thousands of buckets.
  for (double& r : radius) r = r == kInf ? 0 : std::min(r, 4 * cell);  // 0: never a target
  // The discs' box: only the part of a segment inside it is walked (a polygon may reach far
  // beyond the mesh, and its walk must not grow with that).
  double box[4] = {kInf, kInf, -kInf, -kInf};  // min x, min y, max x, max y
  for (uint32_t v = 0; v < n; ++v) {
    if (!(radius[v] > 0)) continue;
    box[0] = std::min(box[0], xy(v)[0] - radius[v]);
    box[1] = std::min(box[1], xy(v)[1] - radius[v]);
    box[2] = std::max(box[2], xy(v)[0] + radius[v]);
    box[3] = std::max(box[3], xy(v)[1] + radius[v]);
  }
  // Each vertex in every bucket (a square of the median edge length) its disc touches.
  auto key = [](int64_t i, int64_t j) { return (static_cast<uint64_t>(i) << 32) ^ uint32_t(j); };
  auto index = [cell](double x) { return static_cast<int64_t>(std::floor(x / cell)); };
  absl::flat_hash_map<uint64_t, std::vector<uint32_t>> buckets;
  for (uint32_t v = 0; v < n; ++v) {
    if (!(radius[v] > 0)) continue;
    const auto [x, y] = xy(v);
    for (int64_t i = index(x - radius[v]); i <= index(x + radius[v]); ++i) {
      for (int64_t j = index(y - radius[v]); j <= index(y + radius[v]); ++j) {
        buckets[key(i, j)].push_back(v);
      }
    }
  }
  const std::vector<uint32_t> none;
  auto in_box = [&](double x, double y) {  // (false for NaN)
    return x >= box[0] && x <= box[2] && y >= box[1] && y <= box[3];
  };
  auto near = [&](double x, double y) -> const std::vector<uint32_t>& {
    if (!in_box(x, y)) return none;
    auto it = buckets.find(key(index(x), index(y)));
    return it == buckets.end() ? none : it->second;
  };
  // The walk's budget in buckets visited, for all outlines together: a polygon of millions of
  // edges across a large DEM stops being snapped (what is left stays as drawn) rather than stall.
  uint64_t budget = 64 * uint64_t{mesh.face_count()} + (uint64_t{1} << 20);
  auto snap_ring = [&](OGRLinearRing& ring, uint64_t* count) {
    std::vector<std::array<double, 2>> in(ring.getNumPoints());
    if (in.empty()) return;
    for (size_t i = 0; i < in.size(); ++i) in[i] = {ring.getX(i), ring.getY(i)};
    for (auto& p : in) {  // corners onto the nearest vertex whose disc holds them
      double best = kInf;
      std::array<double, 2> to = p;
      for (uint32_t v : near(p[0], p[1])) {
        const double d = std::hypot(xy(v)[0] - p[0], xy(v)[1] - p[1]);
        if (d < radius[v] && d < best) best = d, to = xy(v);
      }
      *count += to != p;
      p = to;
    }
    std::vector<std::array<double, 2>> out;
    std::vector<std::pair<double, uint32_t>> on_segment;
    absl::flat_hash_set<uint64_t> seen;
    for (size_t s = 0; s + 1 < in.size(); ++s) {
      const auto p = in[s], q = in[s + 1];
      out.push_back(p);
      const double dx = q[0] - p[0], dy = q[1] - p[1], length = std::hypot(dx, dy);
      if (!(length > 0)) continue;
      // The buckets the segment passes through (sampled every half bucket, with their
      // neighbours): a disc the segment enters lists its vertex in the bucket where it does.
      on_segment.clear();
      seen.clear();
      double t0 = 0, t1 = 1;  // the segment's part inside the box (Liang and Barsky's clip)
      for (int axis = 0; axis < 2; ++axis) {
        const double d = axis == 0 ? dx : dy, from = p[axis];
        if (d == 0) {
          if (from < box[axis] || from > box[axis + 2]) t1 = -1;
          continue;
        }
        const double a = (box[axis] - from) / d, b = (box[axis + 2] - from) / d;
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
      }
      if (!(t1 >= t0)) continue;  // (also NaN: the cutter names coordinates that are not finite)
      // The clipped ends, clamped into the box (rounding of a huge segment's t stays bounded).
      auto clamped = [&](double t) {
        return std::array<double, 2>{std::clamp(p[0] + dx * t, box[0], box[2]),
                                     std::clamp(p[1] + dy * t, box[1], box[3])};
      };
      const auto a = clamped(t0), b = clamped(t1);
      const int64_t steps =
          static_cast<int64_t>(std::ceil(2 * std::hypot(b[0] - a[0], b[1] - a[1]) / cell)) + 1;
      if (budget < uint64_t(steps)) continue;
      budget -= steps;
      for (int64_t k = 0; k <= steps; ++k) {
        const int64_t i0 = index(a[0] + (b[0] - a[0]) * k / steps);
        const int64_t j0 = index(a[1] + (b[1] - a[1]) * k / steps);
        for (int64_t i = i0 - 1; i <= i0 + 1; ++i) {
          for (int64_t j = j0 - 1; j <= j0 + 1; ++j) {
            if (!seen.insert(key(i, j)).second) continue;
            auto it = buckets.find(key(i, j));
            if (it == buckets.end()) continue;
            for (uint32_t v : it->second) {
              const double vx = xy(v)[0] - p[0], vy = xy(v)[1] - p[1];
              const double t = (vx * dx + vy * dy) / length / length;
              if (!(t > 0 && t < 1)) continue;
              if (std::abs(vx * dy - vy * dx) / length < radius[v]) on_segment.push_back({t, v});
            }
          }
        }
      }
      std::sort(on_segment.begin(), on_segment.end());
      for (const auto& [t, v] : on_segment) {
        if (xy(v) == out.back() || xy(v) == q) continue;  // (listed twice, or an end already)
        out.push_back(xy(v));
        ++*count;
      }
    }
    out.push_back(in.back());
    ring.setNumPoints(0);
    for (const auto& [x, y] : out) ring.addPoint(x, y);
  };
  for (FrictionRegion& region : regions) {
    std::unique_ptr<OGRGeometry> drawn(region.shape->clone());
    uint64_t count = 0;
    ForEachRing(*region.shape, [&](OGRLinearRing& ring) { snap_ring(ring, &count); });
    if (count > 0 && !region.shape->IsValid()) {
      region.shape = std::move(drawn);
    }
  }
}

}  // namespace

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

namespace {

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

// GeoJSON text a client sent (a barrier, friction polygons), checked and opened for `use`: its
// "crs" members name CRSs by identifier only (CheckGeoJsonCrs), and it goes into an in-memory file
// of its own that GDAL's GeoJSON driver alone opens. (Given to GDAL as the "file name", text not
// starting with '{' would be taken for a path or a URL: a client could make a server read its
// files or fetch addresses.) Errors start with `name`.
template <typename Result>
absl::StatusOr<Result> WithGeoJsonText(
    const std::string& geojson, const std::string& name,
    const std::function<absl::StatusOr<Result>(GDALDataset&)>& use) {
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
  };
  const size_t first = geojson.find_first_not_of(" \t\r\n");
  if (first == std::string::npos || geojson[first] != '{') {
    return bad("not GeoJSON (a JSON object, starting with '{')");
  }
  CPLJSONDocument document;
  if (!document.LoadMemory(geojson))
    return bad(absl::StrCat("not GeoJSON (", QuietGdal::LastMessage(), ")"));
  if (absl::Status crs = CheckGeoJsonCrs(document.GetRoot(), name); !crs.ok()) return crs;
  MemFile text(".geojson", geojson);
  if (!text.ok()) return absl::InternalError("GDAL cannot make an in-memory file");
  const char* const drivers[] = {"GeoJSON", nullptr};
  GDALDatasetUniquePtr ds(GDALDataset::FromHandle(GDALOpenEx(
      text.path().c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, drivers, nullptr, nullptr)));
  if (ds == nullptr) return bad(absl::StrCat("not GeoJSON (", QuietGdal::LastMessage(), ")"));
  return use(*ds);
}

}  // namespace

absl::StatusOr<MeshData> CutBarrierPolygons(const MeshData& mesh, const std::string& geojson,
                                            const DemInfo* dem, double width,
                                            const std::string& name, CutStats* stats,
                                            uint64_t max_vertices) {
  return CutBarrierPolygons(mesh, std::vector<NamedText>{{geojson, name}}, dem, width, stats,
                            max_vertices);
}

absl::StatusOr<MeshData> CutBarrierPolygons(const MeshData& mesh,
                                            const std::vector<NamedText>& geojsons,
                                            const DemInfo* dem, double width, CutStats* stats,
                                            uint64_t max_vertices) {
  if (geojsons.empty()) return absl::InvalidArgumentError("no barrier polygons");
  QuietGdal quiet;
  OGRSpatialReference file_crs;
  const std::string all_names = absl::StrJoin(
      geojsons, ", ", [](std::string* out, const NamedText& g) { out->append(g.name); });
  if (absl::Status s = ParseFileCrs(dem, all_names, &file_crs); !s.ok()) return s;
  std::unique_ptr<OGRGeometry> barrier;
  for (const NamedText& g : geojsons) {
    absl::StatusOr<std::unique_ptr<OGRGeometry>> polygons =
        WithGeoJsonText<std::unique_ptr<OGRGeometry>>(g.text, g.name, [&](GDALDataset& ds) {
          return BarrierPolygonsOf(&ds, g.name, dem != nullptr ? &file_crs : nullptr);
        });
    if (!polygons.ok()) return polygons.status();
    barrier = barrier == nullptr ? *std::move(polygons)
                                 : JoinCollections(std::move(barrier), *std::move(polygons));
  }
  return CutBarrier(mesh, *barrier, dem, &file_crs, width, max_vertices, all_names, stats);
}

bool IsGeoTiffPath(const std::string& path) {
  const std::string ext = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  return ext == ".tif" || ext == ".tiff";
}

bool LooksLikeTiff(const std::string& bytes) {
  return bytes.size() >= 4 && ((bytes[0] == 'I' && bytes[1] == 'I' &&
                                (bytes[2] == 42 || bytes[2] == 43) && bytes[3] == 0) ||
                               (bytes[0] == 'M' && bytes[1] == 'M' && bytes[2] == 0 &&
                                (bytes[3] == 42 || bytes[3] == 43)));
}

absl::StatusOr<Dem> Dem::Read(const std::string& path, const DemOptions& options) {
  if (options.step < 1) return absl::InvalidArgumentError("--dem-step must be at least 1");
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return absl::NotFoundError(absl::StrCat(path, ": cannot open: No such file or directory"));
  }
  QuietGdal quiet;
  // The user's own file (OpenUserRaster); a VRT is refused by name.
  if (absl::EndsWithIgnoreCase(path, ".vrt")) {
    return absl::InvalidArgumentError(absl::StrCat(
        path,
        ": a VRT is not read (its sources may name other files or URLs); make it a GeoTIFF "
        "(gdal_translate in.vrt out.tif)"));
  }
  GDALDatasetUniquePtr ds = OpenUserRaster(path);
  if (ds == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a raster GDAL reads (", QuietGdal::LastMessage(), ")"));
  }
  return ReadDataset(*ds, path, options);
}

absl::StatusOr<Dem> Dem::ReadGeoTiffBytes(const std::string& bytes, const std::string& name,
                                          const DemOptions& options) {
  if (options.step < 1) return absl::InvalidArgumentError("the DEM step must be at least 1");
  if (!options.barrier_files.empty()) {
    return absl::InvalidArgumentError("a barrier file is read with the DEM's path, not its bytes");
  }
  if (!LooksLikeTiff(bytes)) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": not a GeoTIFF (no TIFF header)"));
  }
  QuietGdal quiet;
  MemFile tiff(".tif", bytes);
  if (!tiff.ok()) return absl::InternalError("GDAL cannot make an in-memory file");
  // Only the GTiff driver parses untrusted bytes; its georeferencing comes from the file alone
  // (no world file or .aux.xml), and no side-car is listed (PrepareGdal, and an empty sibling
  // list).
  const char* const drivers[] = {"GTiff", nullptr};
  const char* const open_options[] = {"GEOREF_SOURCES=INTERNAL", nullptr};
  const char* const no_siblings[] = {nullptr};
  GDALDatasetUniquePtr ds(GDALDataset::FromHandle(GDALOpenEx(
      tiff.path().c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, drivers, open_options, no_siblings)));
  if (ds == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": not a GeoTIFF GDAL reads (", QuietGdal::LastMessage(), ")"));
  }
  // Its CRS may carry PROJ text (a PROJ4 extension, a user-defined citation) naming grid files or
  // +init files, which PROJ would open on the server: refused.
  if (const OGRSpatialReference* srs = ds->GetSpatialRef(); srs != nullptr) {
    if (std::string why = InconsistentCrsId(*srs); !why.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
    }
    char* proj4 = nullptr;
    srs->exportToProj4(&proj4);
    const std::string text = proj4 != nullptr ? proj4 : "";
    CPLFree(proj4);
    for (absl::string_view token : absl::StrSplit(text, ' ', absl::SkipEmpty())) {
      bool names_file = absl::StartsWith(token, "+init=");
      for (const char* key : {"+nadgrids=", "+geoidgrids="}) {
        if (!absl::StartsWith(token, key)) continue;
        for (absl::string_view grid : absl::StrSplit(token.substr(std::strlen(key)), ',')) {
          names_file |= grid != "@null";  // "@null" is no file: the identity
        }
      }
      if (names_file) {
        return absl::InvalidArgumentError(
            absl::StrCat(name, ": its CRS names files (", std::string(token.substr(0, 60)),
                         "); geodex reads no file or URL an upload names"));
      }
    }
  }
  // A GeoTIFF's own metadata can name an overview file (OVERVIEW_FILE in the OVERVIEWS domain),
  // which GDAL opens, path or URL, when overviews are asked for. geodex never asks, and refuses
  // the indirection outright.
  if (CSLCount(ds->GetMetadata("OVERVIEWS")) > 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(name,
                     ": its metadata names an external overview file; geodex reads no file or URL "
                     "an upload names"));
  }
  return ReadDataset(*ds, name, options);
}

absl::StatusOr<Dem> Dem::ReadDataset(GDALDataset& dataset, const std::string& path,
                                     const DemOptions& options) {
  GDALDataset* ds = &dataset;
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", why));
  };
  if (ds->GetRasterCount() != 1) {
    return bad(absl::StrCat("a DEM has one band; this raster has ", ds->GetRasterCount()));
  }
  Dem dem;
  DemInfo& info = dem.info_;
  info.driver = ds->GetDriver() != nullptr ? ds->GetDriver()->GetDescription() : "";
  info.raster_width = static_cast<uint32_t>(ds->GetRasterXSize());
  info.raster_height = static_cast<uint32_t>(ds->GetRasterYSize());
  if (options.max_cells != 0 &&
      uint64_t{info.raster_width} * info.raster_height > options.max_cells) {
    return LimitExceededError(
        Limit::kDemCells,
        absl::StrFormat("%s: %ux%u cells, more than the %u a DEM may have here", path,
                        info.raster_width, info.raster_height, options.max_cells));
  }
  if (!(options.z_tolerance >= 0) || !std::isfinite(options.z_tolerance)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--z-tolerance: must be finite and >= 0 (0: the full grid), got ", options.z_tolerance));
  }
  if (absl::Status s = CheckFrictionSnap(options.friction_snap, !options.friction_file.empty());
      !s.ok()) {
    return s;
  }
  info.step = options.step;
  info.grid_width = (info.raster_width + options.step - 1) / options.step;
  info.grid_height = (info.raster_height + options.step - 1) / options.step;
  if (info.grid_width < 2 || info.grid_height < 2) {
    return bad(absl::StrFormat("%ux%u cells at --dem-step %u; a DEM needs at least 2x2",
                               info.grid_width, info.grid_height, options.step));
  }
  const uint64_t most_vertices = uint64_t{info.grid_width} * info.grid_height;
  const uint64_t most_faces = 2 * uint64_t{info.grid_width - 1} * (info.grid_height - 1);
  if (options.z_tolerance == 0 && options.max_vertices != 0 &&
      most_vertices > options.max_vertices) {
    return LimitExceededError(
        Limit::kVertices,
        absl::StrFormat(
            "%s: %ux%u used cells can make %d vertices, more than the %d a mesh may have here",
            path, info.grid_width, info.grid_height, most_vertices, options.max_vertices));
  }
  if (options.z_tolerance == 0 && options.max_faces != 0 && most_faces > options.max_faces) {
    return LimitExceededError(
        Limit::kFaces,
        absl::StrFormat(
            "%s: %ux%u used cells can make %d faces, more than the %d a mesh may have here", path,
            info.grid_width, info.grid_height, most_faces, options.max_faces));
  }
  double gt[6];
  if (ds->GetGeoTransform(gt) != CE_None) return bad("no geotransform (not georeferenced)");
  if (gt[2] != 0 || gt[4] != 0) return bad("a rotated grid (geotransform terms 2 and 4 not 0)");
  if (!std::all_of(gt, gt + 6, [](double v) { return std::isfinite(v); }) || gt[1] == 0 ||
      gt[5] == 0) {
    return bad("its geotransform is not a grid (a cell size of 0, or not finite)");
  }
  // Cells that doubles cannot tell apart at these coordinates (or, geographic, finer than a
  // centimetre, below what a projection's round trip resolves) make no surface.
  const double reach = std::max({std::abs(gt[0]), std::abs(gt[3]), 1.0});
  if (std::min(std::abs(gt[1]), std::abs(gt[5])) < 1e-9 * reach) {
    return bad(absl::StrFormat("cells of %.3g by %.3g are too small at coordinates near %.6g",
                               std::abs(gt[1]), std::abs(gt[5]), reach));
  }
  const OGRSpatialReference* file_srs = ds->GetSpatialRef();
  if (file_srs == nullptr || file_srs->IsEmpty()) return bad("no coordinate reference system");
  if (std::string why = InconsistentCrsId(*file_srs); !why.empty()) return bad(why);
  OGRSpatialReference file_crs(*file_srs);
  file_crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  info.file_crs_name = file_crs.GetName() != nullptr ? file_crs.GetName() : "";
  info.file_crs_wkt = WktOf(file_crs);

  // The used grid: cell centre (i, j) is the file's pixel centre (i step + 0.5, j step + 0.5).
  const double s = options.step;
  const double corner = 0.5 - s / 2;
  info.geotransform = {gt[0] + corner * gt[1], s * gt[1], 0, gt[3] + corner * gt[5], 0, s * gt[5]};

  // Mesh coordinates: metres, in the file's CRS or (geographic) the UTM zone of the centre.
  TransformPtr to_mesh(nullptr, &OGRCoordinateTransformation::DestroyCT);
  if (file_crs.IsGeographic()) {
    if (std::min(std::abs(gt[1]), std::abs(gt[5])) < 1e-7) {
      return bad("cells finer than 1e-7 degrees (about a centimetre)");
    }
    // The grid must be longitudes and latitudes: at most a turn wide, its rows within the poles
    // (its centre alone, wrapped by PROJ, could pass with cells a million degrees wide).
    const double degrees = DegreesPerUnit(info.file_crs_wkt);
    const double width = std::abs(gt[1]) * info.raster_width * degrees;
    const double top = gt[3] * degrees, bottom = (gt[3] + gt[5] * info.raster_height) * degrees;
    if (!(degrees > 0 && width <= 360 && std::abs(top) <= 90 + 1e-9 &&
          std::abs(bottom) <= 90 + 1e-9)) {
      return bad(absl::StrFormat(
          "a longitude/latitude grid %.9g degrees wide, rows from latitude %.9g to %.9g: at most "
          "360 wide, within [-90, 90]",
          width, std::min(top, bottom), std::max(top, bottom)));
    }
    double lon = gt[0] + gt[1] * info.raster_width / 2.0,
           lat = gt[3] + gt[5] * info.raster_height / 2.0;
    OGRSpatialReference wgs84;
    wgs84.SetWellKnownGeogCS("WGS84");
    wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    TransformPtr to_wgs84 = MakeTransform(file_crs, wgs84);
    if (to_wgs84 == nullptr || !to_wgs84->Transform(1, &lon, &lat)) {
      return bad(
          absl::StrCat("cannot find the DEM's centre in WGS 84 (", QuietGdal::LastMessage(), ")"));
    }
    // A file may count longitudes 0 to 360 (or -360 to 0): its zone is found a turn away.
    if (!(std::abs(lon) <= 360 && std::abs(lat) <= 90)) {
      return bad(absl::StrFormat(
          "its centre (%.9g, %.9g) is not a longitude (within [-360, 360]) and latitude", lon,
          lat));
    }
    lon = std::remainder(lon, 360.0);
    const int zone = std::clamp(static_cast<int>(std::floor((lon + 180) / 6)) + 1, 1, 60);
    OGRSpatialReference utm;
    utm.importFromEPSG((lat >= 0 ? 32600 : 32700) + zone);
    utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    info.reprojected = true;
    info.mesh_crs_name = utm.GetName() != nullptr ? utm.GetName() : "";
    info.mesh_crs_wkt = WktOf(utm);
    // From the stored texts, as a stored DEM rebuilds it (Dem::FromMesh): the same operation.
    to_mesh = FileMeshTransform(info, /*to_mesh=*/true);
    if (to_mesh == nullptr) {
      return bad(absl::StrCat("cannot project to UTM (", QuietGdal::LastMessage(), ")"));
    }
  } else if (file_crs.IsProjected() || file_crs.IsLocal()) {
    info.horizontal_scale = file_crs.GetLinearUnits();
    if (!(info.horizontal_scale > 0)) return bad("the CRS has no linear unit");
    // A foot-based CRS: the mesh is in metres, in that CRS's frame.
    info.mesh_crs_name = info.horizontal_scale == 1
                             ? info.file_crs_name
                             : absl::StrCat(info.file_crs_name, " (x and y in metres)");
    info.mesh_crs_wkt = info.file_crs_wkt;
  } else {
    return bad("the CRS is neither projected nor geographic");
  }

  GDALRasterBand* band = ds->GetRasterBand(1);
  info.vertical_unit = band->GetUnitType() != nullptr ? band->GetUnitType() : "";
  const double unit = MetresPerHeightUnit(info.vertical_unit);
  if (unit == 0) {
    return bad(
        absl::StrCat("height unit '", info.vertical_unit, "' is not m, ft or US survey foot"));
  }
  int has_scale = 0, has_offset = 0;
  double scale = band->GetScale(&has_scale), offset = band->GetOffset(&has_offset);
  if (!has_scale) scale = 1;
  if (!has_offset) offset = 0;
  info.vertical_scale = unit * scale;
  // Which cells have data: GDAL's mask (the nodata value compared in the band's own type, or a
  // per-dataset mask or alpha band), plus NaN.
  GDALRasterBand* mask = band->GetMaskBand();
  std::vector<uint8_t> valid(info.raster_width);
  if (uint64_t{info.grid_width} * info.grid_height >= kNoVertex) {
    return bad(absl::StrFormat("%ux%u cells: more than a mesh can index; use --dem-step",
                               info.grid_width, info.grid_height));
  }

  // Vertices: the used cells with data, row by row (one file row read at a time).
  const uint32_t W = info.grid_width, H = info.grid_height;
  dem.vertex_of_cell_.assign(size_t{W} * H, kNoVertex);
  std::vector<double> row(info.raster_width);
  std::vector<double> xs, ys;
  uint32_t next = 0;
  for (uint32_t j = 0; j < H; ++j) {
    if (band->RasterIO(GF_Read, 0, static_cast<int>(j * options.step), info.raster_width, 1,
                       row.data(), info.raster_width, 1, GDT_Float64, 0, 0) != CE_None) {
      return bad(absl::StrCat("read error (", QuietGdal::LastMessage(), ")"));
    }
    if (mask->RasterIO(GF_Read, 0, static_cast<int>(j * options.step), info.raster_width, 1,
                       valid.data(), info.raster_width, 1, GDT_Byte, 0, 0) != CE_None) {
      return bad(absl::StrCat("read error in the nodata mask (", QuietGdal::LastMessage(), ")"));
    }
    for (uint32_t i = 0; i < W; ++i) {
      const double raw = row[size_t{i} * options.step];
      if (!std::isfinite(raw) || valid[size_t{i} * options.step] == 0) {
        ++info.nodata_cells;
        continue;
      }
      if ((raw * scale + offset) * unit < options.barrier_below) {
        ++info.barrier_cells;
        continue;
      }
      dem.vertex_of_cell_[size_t{j} * W + i] = next++;
      const double px = (i + 0.5) * info.geotransform[1] + info.geotransform[0];
      const double py = (j + 0.5) * info.geotransform[5] + info.geotransform[3];
      xs.push_back(px);
      ys.push_back(py);
      dem.mesh_.positions.insert(
          dem.mesh_.positions.end(),
          {px * info.horizontal_scale, py * info.horizontal_scale, (raw * scale + offset) * unit});
    }
  }
  if (to_mesh != nullptr && next > 0) {
    std::vector<int> ok(next);
    if (!to_mesh->Transform(static_cast<int>(next), xs.data(), ys.data(), nullptr, ok.data()) ||
        std::find(ok.begin(), ok.end(), 0) != ok.end()) {
      return bad(absl::StrCat("cannot project the cells to ", info.mesh_crs_name));
    }
    for (uint32_t v = 0; v < next; ++v) {
      dem.mesh_.positions[3 * size_t{v}] = xs[v];
      dem.mesh_.positions[3 * size_t{v} + 1] = ys[v];
    }
  }

  // A barrier drawn as polygons: one union in the file's CRS, cut out of the mesh once it is made.
  // Several files add up: their features go into the one collection, as one file holding them all.
  std::unique_ptr<OGRGeometry> barrier;
  const std::string barrier_name = BarrierFilesName(options.barrier_files);
  for (const std::string& path : options.barrier_files) {
    const std::string name = absl::StrCat("--barrier ", path);
    absl::StatusOr<GDALDatasetUniquePtr> file = OpenBarrierFile(path, name);
    if (!file.ok()) return file.status();
    absl::StatusOr<std::unique_ptr<OGRGeometry>> polygons =
        BarrierPolygonsOf(file->get(), name, &file_crs);
    if (!polygons.ok()) return polygons.status();
    barrier = barrier == nullptr ? *std::move(polygons)
                                 : JoinCollections(std::move(barrier), *std::move(polygons));
  }
  // Friction regions: their outlines cut in once the barrier is out (geodex/friction.h).
  std::vector<FrictionRegion> friction_regions;
  const std::string friction_name = absl::StrCat("--friction ", options.friction_file);
  if (!options.friction_file.empty()) {
    absl::StatusOr<GDALDatasetUniquePtr> file =
        OpenBarrierFile(options.friction_file, friction_name);
    if (!file.ok()) return file.status();
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(**file, &file_crs, friction_name);
    if (!regions.ok()) return regions.status();
    friction_regions = *std::move(regions);
  }
  std::vector<double> face_friction;  // the cut mesh's (Dem::face_friction)
  // What is drawn on the mesh once it is made: the barrier cut out, then the outlines cut in.
  auto cut_drawn = [&](MeshData mesh) -> absl::StatusOr<MeshData> {
    if (barrier != nullptr) {
      CutStats stats;
      absl::StatusOr<MeshData> cut =
          CutBarrier(mesh, *barrier, &info, &file_crs, options.barrier_width, options.max_vertices,
                     barrier_name, &stats);
      if (!cut.ok()) return cut.status();
      if (cut->faces.empty()) return bad("the barrier covers every face: nothing is left");
      info.barrier_faces = stats.faces_removed + stats.faces_cut;
      mesh = *std::move(cut);
    }
    if (!friction_regions.empty()) {
      // In the mesh's x y, snapped there (friction_snap), cut in, and every face valued from
      // those same shapes: a snapped outline is where the values change.
      if (absl::Status s = RegionsToMeshFrame(friction_regions, info, file_crs, friction_name);
          !s.ok()) {
        return s;
      }
      if (options.friction_snap > 0) {
        SnapOutlinesToVertices(friction_regions, mesh, options.friction_snap);
      }
      CutStats stats;
      absl::StatusOr<MeshData> cut =
          CutOutlines(mesh, *OutlinesOf(friction_regions), /*dem=*/nullptr, /*file_crs=*/nullptr,
                      options.max_vertices, friction_name, &stats);
      if (!cut.ok()) return cut.status();
      absl::StatusOr<std::vector<double>> values =
          FaceFrictionOf(std::move(friction_regions), *cut, /*dem=*/nullptr, friction_name);
      if (!values.ok()) return values.status();
      face_friction = *std::move(values);
      mesh = *std::move(cut);
    }
    return mesh;
  };
  auto made = [&](MeshData drawn) {
    absl::StatusOr<Dem> out = FromMesh(std::move(drawn), info);
    if (out.ok()) out->face_friction_ = std::move(face_friction);
    return out;
  };

  // Faces: per block, corners a (i, j), b (i+1, j), c (i, j+1), d (i+1, j+1), split along a-d:
  // (a, c, d) and (a, d, b), counter-clockwise seen from above when rows run south (gt[5] < 0).
  const bool flip = gt[1] * gt[5] > 0;  // rows run north: mirror the winding
  if (options.z_tolerance > 0) {
    absl::StatusOr<MeshData> tin = BuildTin(dem, options, flip, file_crs, path, &info);
    if (!tin.ok()) return tin.status();
    info.z_tolerance = options.z_tolerance;
    absl::StatusOr<MeshData> drawn = cut_drawn(*std::move(tin));
    if (!drawn.ok()) return drawn.status();
    return made(*std::move(drawn));
  }
  dem.face_of_block_.assign(2 * size_t{W - 1} * (H - 1), kNoVertex);
  for (uint32_t j = 0; j + 1 < H; ++j) {
    for (uint32_t i = 0; i + 1 < W; ++i) {
      const uint32_t a = dem.VertexAt(i, j), b = dem.VertexAt(i + 1, j);
      const uint32_t c = dem.VertexAt(i, j + 1), d = dem.VertexAt(i + 1, j + 1);
      const std::array<std::array<uint32_t, 3>, 2> tris = {{{a, c, d}, {a, d, b}}};
      for (int k = 0; k < 2; ++k) {
        std::array<uint32_t, 3> t = tris[k];
        if (t[0] == kNoVertex || t[1] == kNoVertex || t[2] == kNoVertex) continue;
        if (flip) std::swap(t[1], t[2]);
        dem.face_of_block_[2 * (size_t{j} * (W - 1) + i) + k] =
            static_cast<uint32_t>(dem.mesh_.face_count());
        dem.mesh_.faces.insert(dem.mesh_.faces.end(), t.begin(), t.end());
      }
    }
  }
  if (dem.mesh_.faces.empty()) {
    return bad(info.barrier_cells > 0
                   ? "no 2x2 block of cells above the barrier: nothing to triangulate"
                   : "no 2x2 block of cells with data: nothing to triangulate");
  }
  if (barrier == nullptr && friction_regions.empty()) return dem;
  absl::StatusOr<MeshData> drawn = cut_drawn(dem.mesh_);
  if (!drawn.ok()) return drawn.status();
  return made(*std::move(drawn));
}

absl::StatusOr<std::array<double, 2>> Dem::CellCentreInMesh(uint32_t col, uint32_t row) const {
  const std::array<double, 6>& gt = info_.geotransform;
  double x = gt[0] + (col + 0.5) * gt[1], y = gt[3] + (row + 0.5) * gt[5];
  if (!info_.reprojected)
    return std::array<double, 2>{x * info_.horizontal_scale, y * info_.horizontal_scale};
  QuietGdal quiet;
  TransformPtr t = FileMeshTransform(info_, /*to_mesh=*/true);
  if (t == nullptr || !t->Transform(1, &x, &y)) {
    return absl::InvalidArgumentError("a cell centre does not project to the mesh's CRS");
  }
  return std::array<double, 2>{x, y};
}

absl::StatusOr<MeshData> Dem::BuildTin(const Dem& grid, const DemOptions& options, bool flip,
                                       const OGRSpatialReference& file_crs, const std::string& name,
                                       DemInfo* info) {
  const uint32_t W = grid.info_.grid_width, H = grid.info_.grid_height;
  // Heights in metres, row by row (the tolerance is in metres too); cells without data (or below
  // the barrier) are holes: they do not shape the TIN, and are cut out of it below.
  std::vector<double> heights(size_t{W} * H, 0.0);
  std::vector<uint8_t> valid(size_t{W} * H, 0);
  bool holes = false;
  for (size_t cell = 0; cell < heights.size(); ++cell) {
    const uint32_t v = grid.vertex_of_cell_[cell];
    holes |= v == kNoVertex;
    if (v == kNoVertex) continue;
    heights[cell] = grid.mesh_.positions[3 * size_t{v} + 2];
    valid[cell] = 1;
  }
  AdaptiveTinOptions tin_options;
  tin_options.z_tolerance = options.z_tolerance * grid.info_.vertical_scale;
  tin_options.max_vertices = options.max_vertices;
  absl::StatusOr<AdaptiveTin> tin =
      BuildAdaptiveTin(heights.data(), H, W, holes ? valid.data() : nullptr, tin_options);
  if (!tin.ok()) {
    if (absl::IsInvalidArgument(tin.status())) {
      return absl::InvalidArgumentError(
          absl::StrCat("--z-tolerance: ", name, ": ", tin.status().message()));
    }
    return tin.status();
  }
  if (options.max_faces != 0 && tin->faces.size() > options.max_faces) {
    return LimitExceededError(
        Limit::kFaces, absl::StrFormat("%s: the TIN has %d faces, more than the %d a mesh may "
                                       "have here (a larger --z-tolerance makes fewer)",
                                       name, tin->faces.size(), options.max_faces));
  }
  // Vertices in row order (what FromMesh reads a DEM's cells by), faces wound like the grid's. A
  // corner in a hole keeps the height the TIN gave it (it is cut away with the hole).
  const size_t n = tin->vertices.size();
  std::vector<uint32_t> order(n), new_index(n);
  for (uint32_t v = 0; v < n; ++v) order[v] = v;
  auto cell_of = [&](uint32_t v) {
    return size_t{tin->source_cell[v].first} * W + tin->source_cell[v].second;
  };
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return cell_of(a) < cell_of(b); });
  MeshData out;
  out.positions.reserve(3 * n);
  for (uint32_t k = 0; k < n; ++k) {
    new_index[order[k]] = k;
    const uint32_t v = grid.vertex_of_cell_[cell_of(order[k])];
    if (v != kNoVertex) {
      const double* p = &grid.mesh_.positions[3 * size_t{v}];
      out.positions.insert(out.positions.end(), p, p + 3);
    } else {  // a corner in a hole: its map position, the TIN's height
      absl::StatusOr<std::array<double, 2>> xy = grid.CellCentreInMesh(
          tin->source_cell[order[k]].second, tin->source_cell[order[k]].first);
      if (!xy.ok()) return xy.status();
      out.positions.insert(out.positions.end(), {(*xy)[0], (*xy)[1], tin->vertices[order[k]][2]});
    }
  }
  out.faces.reserve(3 * tin->faces.size());
  for (const std::array<uint32_t, 3>& f : tin->faces) {
    // The TIN's faces turn counter-clockwise in (column, row); the grid's (a, c, d) clockwise
    // there (rows run south), mirrored when they run north.
    std::array<uint32_t, 3> t = {new_index[f[0]], new_index[f[1]], new_index[f[2]]};
    if (!flip) std::swap(t[1], t[2]);
    out.faces.insert(out.faces.end(), t.begin(), t.end());
  }
  info->max_vertical_deviation = tin->max_vertical_deviation;
  info->rms_vertical_deviation = tin->rms_vertical_deviation;
  if (!holes) return out;
  // The grid's holes, exactly: a grid triangle goes when a corner has no data, so a hole cell
  // takes the six triangles around it, a hexagon of cell centres; a row's run of hole cells
  // i0..i1 takes their union, (i0-1, j-1) (i1, j-1) (i1+1, j) (i1+1, j+1) (i0, j+1) (i0-1, j).
  const std::array<double, 6>& gt = grid.info_.geotransform;
  auto at = [&](double i, double j) {
    return std::pair{gt[0] + (i + 0.5) * gt[1], gt[3] + (j + 0.5) * gt[5]};
  };
  OGRMultiPolygon runs;
  for (uint32_t j = 0; j < H; ++j) {
    for (uint32_t i = 0; i < W;) {
      if (valid[size_t{j} * W + i]) {
        ++i;
        continue;
      }
      uint32_t end = i;
      while (end + 1 < W && !valid[size_t{j} * W + end + 1]) ++end;
      const double i0 = i, i1 = end, jj = j;
      OGRLinearRing ring;
      for (auto [u, v] : {std::pair{i0 - 1, jj - 1}, std::pair{i1, jj - 1}, std::pair{i1 + 1, jj},
                          std::pair{i1 + 1, jj + 1}, std::pair{i0, jj + 1}, std::pair{i0 - 1, jj},
                          std::pair{i0 - 1, jj - 1}}) {
        const auto [x, y] = at(u, v);
        ring.addPoint(x, y);
      }
      OGRPolygon hexagon;
      hexagon.addRing(&ring);
      runs.addGeometry(&hexagon);
      i = end + 1;
    }
  }
  std::unique_ptr<OGRGeometry> cut_out(runs.UnionCascaded());
  if (cut_out == nullptr) {
    return absl::InternalError(absl::StrCat(name, ": cannot join the DEM's holes (GEOS)"));
  }
  CutStats stats;
  return CutBarrier(out, *cut_out, &grid.info_, &file_crs, 0, options.max_vertices,
                    absl::StrCat(name, " (its cells without data)"), &stats);
}

absl::StatusOr<Dem> Dem::FromMesh(MeshData mesh, DemInfo info) {
  auto bad = [](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat("not the mesh of this DEM: ", why));
  };
  const uint32_t W = info.grid_width, H = info.grid_height;
  const std::array<double, 6>& gt = info.geotransform;
  if (W < 2 || H < 2 || uint64_t{W} * H >= kNoVertex || gt[1] == 0 || gt[5] == 0 ||
      !(info.horizontal_scale > 0)) {
    return bad("its grid is not a DEM's");
  }
  const size_t n = mesh.vertex_count();
  // The grid maps are W x H: bounded by the mesh (a DEM up to 255 of 256 cells without data),
  // whatever a header says.
  // (A TIN's grid may be far larger than its mesh: up to 2^28 cells, 1 GiB of maps.)
  if (info.z_tolerance > 0 ? uint64_t{W} * H > (uint64_t{1} << 28)
                           : uint64_t{W} * H > 256 * (uint64_t{n} + 1) + (uint64_t{1} << 24)) {
    return bad("its grid is far larger than its mesh");
  }
  // Each vertex's map position in the file's CRS.
  std::vector<double> xs(n), ys(n);
  for (size_t v = 0; v < n; ++v) {
    xs[v] = mesh.positions[3 * v];
    ys[v] = mesh.positions[3 * v + 1];
  }
  if (info.reprojected) {
    QuietGdal quiet;
    TransformPtr back = FileMeshTransform(info, /*to_mesh=*/false);
    if (back == nullptr) return bad("its CRS does not parse, or does not project");
    std::vector<int> ok(n);
    if (back == nullptr ||
        (n > 0 &&
         !back->Transform(static_cast<int>(n), xs.data(), ys.data(), nullptr, ok.data())) ||
        std::find(ok.begin(), ok.end(), 0) != ok.end()) {
      return bad("its vertices do not project back to the file's CRS");
    }
    LongitudesToGrid(info, xs.data(), n);
  } else {
    for (size_t v = 0; v < n; ++v) {
      xs[v] /= info.horizontal_scale;
      ys[v] /= info.horizontal_scale;
    }
  }
  // Reprojected, which cell centre a vertex is at is decided in the mesh's metres: its nearest
  // centre, projected forward as the reader projected it, must be where the vertex is (0.1 mm).
  // The way back only finds the candidate: between datums (WGS 72 to WGS 84's UTM) PROJ's 2D
  // round trip is off by up to 1e-10 degrees, a thousandth of the finest cell the reader takes.
  std::vector<char> at_centre(n, 0);
  if (info.reprojected) {
    std::vector<double> cx(n), cy(n);
    for (size_t v = 0; v < n; ++v) {
      const double u = (xs[v] - gt[0]) / gt[1] - 0.5, w = (ys[v] - gt[3]) / gt[5] - 0.5;
      cx[v] = gt[0] + (std::round(u) + 0.5) * gt[1];
      cy[v] = gt[3] + (std::round(w) + 0.5) * gt[5];
    }
    QuietGdal quiet;
    TransformPtr forward = FileMeshTransform(info, /*to_mesh=*/true);
    std::vector<int> ok(n);
    if (forward == nullptr || (n > 0 && !forward->Transform(static_cast<int>(n), cx.data(),
                                                            cy.data(), nullptr, ok.data()))) {
      return bad("its cell centres do not project to the mesh's CRS");
    }
    for (size_t v = 0; v < n; ++v) {
      at_centre[v] = ok[v] && std::abs(cx[v] - mesh.positions[3 * v]) < 1e-4 &&
                     std::abs(cy[v] - mesh.positions[3 * v + 1]) < 1e-4;
    }
  }
  Dem dem;
  dem.vertex_of_cell_.assign(size_t{W} * H, kNoVertex);
  // The cells' vertices come first, in row order; after them, a barrier cut's (at no cell centre).
  std::vector<uint32_t> cell_of_vertex(n, kNoVertex);
  size_t previous = 0, cells = 0;
  for (size_t v = 0; v < n; ++v) {
    const double u = (xs[v] - gt[0]) / gt[1] - 0.5, w = (ys[v] - gt[3]) / gt[5] - 0.5;
    const double i = std::round(u), j = std::round(w);
    // A cell centre to far better than a cell (in the file's own units, exact to ~1e-12 of one).
    const bool near =
        info.reprojected ? at_centre[v] != 0 : std::abs(u - i) < 1e-6 && std::abs(w - j) < 1e-6;
    const bool centre = near && i >= 0 && j >= 0 && i < W && j < H;
    const size_t cell = centre ? static_cast<size_t>(j) * W + static_cast<size_t>(i) : 0;
    if (!centre || (v > 0 && cell <= previous)) {
      if (v == 0) return bad("vertex 0 is not at a cell centre");
      break;
    }
    previous = cell;
    dem.vertex_of_cell_[cell] = static_cast<uint32_t>(v);
    cell_of_vertex[v] = static_cast<uint32_t>(cell);
    ++cells;
  }
  for (size_t v = cells; v < n; ++v) {  // a cut's vertices lie within the grid, at no cell centre
    const double u = (xs[v] - gt[0]) / gt[1] - 0.5, w = (ys[v] - gt[3]) / gt[5] - 0.5;
    const double slack = info.reprojected ? 1e-2 : 1e-6;  // the way back's error, as above
    if (!(u >= -slack && w >= -slack && u <= W - 1 + slack && w <= H - 1 + slack)) {
      return bad(absl::StrCat("vertex ", v, " is outside the grid"));
    }
    // On the grid a cut's vertex is at a cell centre only as a copy of that cell's vertex (a line
    // barrier's two sides); on a TIN also where a hole's outline turns (most cells are no vertex).
    const bool near =
        info.reprojected ? at_centre[v] != 0
                         : std::abs(u - std::round(u)) < 1e-6 && std::abs(w - std::round(w)) < 1e-6;
    if (info.z_tolerance == 0 && near) {
      const size_t cell =
          static_cast<size_t>(std::round(w)) * W + static_cast<size_t>(std::round(u));
      const uint32_t original =
          std::round(u) < W && std::round(w) < H ? dem.vertex_of_cell_[cell] : kNoVertex;
      if (original == kNoVertex || !std::equal(&mesh.positions[3 * v], &mesh.positions[3 * v] + 3,
                                               &mesh.positions[3 * size_t{original}])) {
        return bad(absl::StrCat("vertex ", v, " is out of row order"));
      }
    }
  }
  if (info.z_tolerance > 0) {  // an adaptive TIN: its faces are not blocks
    dem.cell_uv_.resize(n);
    for (size_t v = 0; v < n; ++v) {
      dem.cell_uv_[v] = {(xs[v] - gt[0]) / gt[1] - 0.5, (ys[v] - gt[3]) / gt[5] - 0.5};
    }
    dem.mesh_ = std::move(mesh);
    dem.info_ = std::move(info);
    if (absl::Status mapped = dem.MapTin(); !mapped.ok()) return bad(std::string(mapped.message()));
    return dem;
  }
  dem.face_of_block_.assign(2 * size_t{W - 1} * (H - 1), kNoVertex);
  std::vector<std::pair<uint64_t, uint32_t>> pieces;  // (block triangle, face) of a cut's faces
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    uint32_t ci[3], cj[3];
    bool on_cells = true;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = mesh.faces[3 * f + c];
      if (v >= n) return bad(absl::StrCat("face ", f, " has no vertex ", v));
      on_cells &= cell_of_vertex[v] != kNoVertex;
      ci[c] = on_cells ? cell_of_vertex[v] % W : 0;
      cj[c] = on_cells ? cell_of_vertex[v] / W : 0;
    }
    if (!on_cells) {
      // A piece of a cut face: filed under the block triangle that holds its centre, found again
      // by DropMeshPoint among that triangle's neighbours too.
      double u = 0, w = 0;
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = mesh.faces[3 * f + c];
        u += ((xs[v] - gt[0]) / gt[1] - 0.5) / 3;
        w += ((ys[v] - gt[3]) / gt[5] - 0.5) / 3;
      }
      const uint32_t i = static_cast<uint32_t>(std::clamp(std::floor(u), 0.0, W - 2.0));
      const uint32_t j = static_cast<uint32_t>(std::clamp(std::floor(w), 0.0, H - 2.0));
      const int k = (w - j) >= (u - i) ? 0 : 1;  // (a, c, d) below the a-d diagonal, else (a, d, b)
      pieces.push_back({2 * (uint64_t{j} * (W - 1) + i) + k, static_cast<uint32_t>(f)});
      continue;
    }
    const uint32_t i = std::min({ci[0], ci[1], ci[2]}), j = std::min({cj[0], cj[1], cj[2]});
    // (a, c, d) has the block's lower-left corner c (i, j + 1); (a, d, b) its b (i + 1, j).
    int k = -1, corners = 0;
    for (int c = 0; c < 3; ++c) {
      const uint32_t di = ci[c] - i, dj = cj[c] - j;
      if (di > 1 || dj > 1) break;
      corners |= 1 << (di + 2 * dj);  // a 1, b 2, c 4, d 8
    }
    if (corners == (1 | 4 | 8)) k = 0;
    if (corners == (1 | 8 | 2)) k = 1;
    if (k < 0 || i + 1 >= W || j + 1 >= H) {
      return bad(absl::StrCat("face ", f, " is not one of a block's two triangles"));
    }
    uint32_t& slot = dem.face_of_block_[2 * (size_t{j} * (W - 1) + i) + k];
    if (slot != kNoVertex) return bad(absl::StrCat("face ", f, " repeats face ", slot));
    slot = static_cast<uint32_t>(f);
  }
  std::sort(pieces.begin(), pieces.end());
  dem.pieces_ = std::move(pieces);
  dem.mesh_ = std::move(mesh);
  dem.info_ = std::move(info);
  return dem;
}

namespace {

// Barycentrics of (u, v) in the triangle p0 p1 p2 of the plane; false when it is degenerate.
bool Barycentrics(const std::array<double, 2>& p0, const std::array<double, 2>& p1,
                  const std::array<double, 2>& p2, double u, double v, std::array<double, 3>* b) {
  const double det = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]);
  if (det == 0) return false;
  const double b1 = ((u - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (v - p0[1])) / det;
  const double b2 = ((p1[0] - p0[0]) * (v - p0[1]) - (u - p0[0]) * (p1[1] - p0[1])) / det;
  *b = {1 - b1 - b2, b1, b2};
  return true;
}

// A face point from barycentrics a hair outside the face: clamped and normalised.
SurfacePoint ClampedFacePoint(uint32_t face, std::array<double, 3> b) {
  double sum = 0;
  for (double& x : b) sum += (x = x > 0 ? x : 0.0);  // also turns -0 into 0
  return SurfacePoint::InFace(face, b[0] / sum, b[1] / sum, b[2] / sum);
}

}  // namespace

absl::Status Dem::MapTin() {
  const uint32_t W = info_.grid_width, H = info_.grid_height;
  const size_t faces = mesh_.face_count(), n = mesh_.vertex_count();
  for (uint32_t v : mesh_.faces) {
    if (v >= n) return absl::InvalidArgumentError(absl::StrCat("a face has no vertex ", v));
  }
  // Neighbours across each edge (the edge opposite corner k), from the edges sorted by their ends.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * faces);
  for (size_t f = 0; f < faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = mesh_.faces[3 * f + (k + 1) % 3], b = mesh_.faces[3 * f + (k + 2) % 3];
      edges.push_back({std::min(a, b) << 32 | std::max(a, b), static_cast<uint32_t>(3 * f + k)});
    }
  }
  std::sort(edges.begin(), edges.end());
  neighbours_.assign(3 * faces, kNoVertex);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 2) {  // an inner edge (a non-manifold one stays a boundary for the walk)
      neighbours_[edges[i].second] = edges[i + 1].second / 3;
      neighbours_[edges[i + 1].second] = edges[i].second / 3;
    }
    i = j;
  }
  // The face holding each cell centre: each face's cells, over its bounding box (TIN faces are
  // Delaunay triangles of the grid's cells: their boxes hold about twice their cells).
  face_of_cell_.assign(size_t{W} * H, kNoVertex);
  constexpr double kOn = 1e-9;  // a centre on an edge belongs to the first face that finds it
  for (size_t f = 0; f < faces; ++f) {
    const std::array<double, 2>& p0 = cell_uv_[mesh_.faces[3 * f]];
    const std::array<double, 2>& p1 = cell_uv_[mesh_.faces[3 * f + 1]];
    const std::array<double, 2>& p2 = cell_uv_[mesh_.faces[3 * f + 2]];
    const double lo_u = std::max(0.0, std::ceil(std::min({p0[0], p1[0], p2[0]}) - kOn));
    const double hi_u = std::min(W - 1.0, std::floor(std::max({p0[0], p1[0], p2[0]}) + kOn));
    const double lo_v = std::max(0.0, std::ceil(std::min({p0[1], p1[1], p2[1]}) - kOn));
    const double hi_v = std::min(H - 1.0, std::floor(std::max({p0[1], p1[1], p2[1]}) + kOn));
    for (double v = lo_v; v <= hi_v; ++v) {
      for (double u = lo_u; u <= hi_u; ++u) {
        std::array<double, 3> b;
        if (!Barycentrics(p0, p1, p2, u, v, &b) || std::min({b[0], b[1], b[2]}) < -kOn) continue;
        uint32_t& slot = face_of_cell_[static_cast<size_t>(v) * W + static_cast<size_t>(u)];
        if (slot == kNoVertex) slot = static_cast<uint32_t>(f);
      }
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<SurfacePoint> Dem::DropOnTin(double /*mx*/, double /*my*/, double u, double v,
                                            const std::string& name) const {
  // Faces and cells share the grid's plane (the TIN was made there): walk from the face of a cell
  // near the point towards it, across the edge it lies beyond, until a face holds it.
  const int W = static_cast<int>(info_.grid_width), H = static_cast<int>(info_.grid_height);
  const int ci = std::clamp(static_cast<int>(std::lround(u)), 0, W - 1);
  const int cj = std::clamp(static_cast<int>(std::lround(v)), 0, H - 1);
  std::vector<uint32_t> starts;
  for (int r = 0; r <= 2 && starts.empty(); ++r) {
    for (int j = std::max(0, cj - r); j <= std::min(H - 1, cj + r); ++j) {
      for (int i = std::max(0, ci - r); i <= std::min(W - 1, ci + r); ++i) {
        const uint32_t f = face_of_cell_[size_t(j) * W + i];
        if (f != kNoVertex && std::find(starts.begin(), starts.end(), f) == starts.end()) {
          starts.push_back(f);
        }
      }
    }
  }
  const size_t faces = mesh_.face_count();
  for (uint32_t f : starts) {
    for (size_t step = 0; step <= faces; ++step) {
      std::array<double, 3> b;
      if (!Barycentrics(cell_uv_[mesh_.faces[3 * size_t{f}]],
                        cell_uv_[mesh_.faces[3 * size_t{f} + 1]],
                        cell_uv_[mesh_.faces[3 * size_t{f} + 2]], u, v, &b)) {
        break;
      }
      const int k = static_cast<int>(std::min_element(b.begin(), b.end()) - b.begin());
      if (b[k] >= -1e-12) return ClampedFacePoint(f, b);
      const uint32_t next = neighbours_[3 * size_t{f} + k];
      if (next == kNoVertex) {
        if (b[k] >= -1e-7) return ClampedFacePoint(f, b);  // on the boundary, to round-off
        break;  // beyond a boundary here: another start may go round
      }
      f = next;
    }
  }
  return absl::InvalidArgumentError(
      absl::StrCat(name, ": in a hole of the DEM (nodata or a barrier)"));
}

absl::StatusOr<SurfacePoint> Dem::CellPoint(uint32_t col, uint32_t row) const {
  if (col >= info_.grid_width || row >= info_.grid_height) {
    return absl::InvalidArgumentError(absl::StrCat("cell (", col, ", ", row, ") is off the grid"));
  }
  const size_t cell = size_t{row} * info_.grid_width + col;
  if (!is_tin()) {
    if (vertex_of_cell_[cell] == kNoVertex) return absl::NotFoundError("a cell without surface");
    return SurfacePoint::AtVertex(vertex_of_cell_[cell]);
  }
  const uint32_t f = face_of_cell_[cell];
  if (f == kNoVertex) return absl::NotFoundError("a cell without surface");
  if (vertex_of_cell_[cell] != kNoVertex) return SurfacePoint::AtVertex(vertex_of_cell_[cell]);
  std::array<double, 3> b;
  if (!Barycentrics(cell_uv_[mesh_.faces[3 * size_t{f}]], cell_uv_[mesh_.faces[3 * size_t{f} + 1]],
                    cell_uv_[mesh_.faces[3 * size_t{f} + 2]], col, row, &b)) {
    return absl::NotFoundError("a cell on a degenerate face");
  }
  return ClampedFacePoint(f, b);
}

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

// WGS 84 longitude/latitude to the DEM file's CRS (from_wgs84), or back.
TransformPtr Wgs84Transform(const DemInfo& info, bool from_wgs84) {
  OGRSpatialReference wgs84, file_crs;
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  file_crs.importFromWkt(info.file_crs_wkt.c_str());
  file_crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return from_wgs84 ? MakeTransform(wgs84, file_crs) : MakeTransform(file_crs, wgs84);
}

bool OutsideTheDem(const absl::Status& status) {
  return absl::IsInvalidArgument(status) && absl::EndsWith(status.message(), ": outside the DEM");
}
}  // namespace

bool Dem::InGrid(double x, double y) const {
  const std::array<double, 6>& gt = info_.geotransform;
  const double u = (x - gt[0]) / gt[1] - 0.5, v = (y - gt[3]) / gt[5] - 0.5;
  return u >= 0 && v >= 0 && u <= info_.grid_width - 1.0 && v <= info_.grid_height - 1.0;
}

absl::StatusOr<std::array<double, 4>> Dem::LonLatExtent() const {
  QuietGdal quiet;
  TransformPtr t = Wgs84Transform(info_, /*from_wgs84=*/false);
  if (t == nullptr) return absl::InternalError("the DEM's CRS does not project to WGS 84");
  // The used cells' centres around the grid's edge (a projection bends straight lines).
  const std::array<double, 6>& gt = info_.geotransform;
  std::array<double, 4> box = {
      std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
      -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  const uint32_t W = info_.grid_width, H = info_.grid_height;
  for (int k = 0; k <= 64; ++k) {
    const double f = k / 64.0;
    for (auto [u, v] : {std::pair{f * (W - 1), 0.0}, std::pair{f * (W - 1), H - 1.0},
                        std::pair{0.0, f * (H - 1)}, std::pair{W - 1.0, f * (H - 1)}}) {
      double x = gt[0] + (u + 0.5) * gt[1], y = gt[3] + (v + 0.5) * gt[5];
      if (!t->Transform(1, &x, &y)) continue;
      box = {std::min(box[0], x), std::min(box[1], y), std::max(box[2], x), std::max(box[3], y)};
    }
  }
  return box;
}

absl::StatusOr<SurfacePoint> Dem::DropMapPoint(double x, double y) const {
  absl::StatusOr<SurfacePoint> p =
      DropNamed(x, y, absl::StrCat("g:", Shortest(x), ":", Shortest(y)));
  if (!OutsideTheDem(p.status())) return p;
  // Where the DEM is, in the same coordinates, and whether x and y were given the other way round.
  const std::array<double, 6>& gt = info_.geotransform;
  const double x0 = gt[0] + 0.5 * gt[1], x1 = gt[0] + (info_.grid_width - 0.5) * gt[1];
  const double y0 = gt[3] + 0.5 * gt[5], y1 = gt[3] + (info_.grid_height - 0.5) * gt[5];
  std::string message = absl::StrFormat("%s (it covers x %.10g to %.10g, y %.10g to %.10g in %s)",
                                        p.status().message(), std::min(x0, x1), std::max(x0, x1),
                                        std::min(y0, y1), std::max(y0, y1), info_.file_crs_name);
  if (InGrid(y, x))
    absl::StrAppend(&message, "; g:", Shortest(y), ":", Shortest(x),
                    " would be inside (x and y swapped?)");
  return absl::InvalidArgumentError(message);
}

absl::StatusOr<SurfacePoint> Dem::DropNamed(double x, double y, const std::string& name) const {
  const std::array<double, 6>& gt = info_.geotransform;
  const double u = (x - gt[0]) / gt[1] - 0.5, v = (y - gt[3]) / gt[5] - 0.5;
  double mx = x * info_.horizontal_scale, my = y * info_.horizontal_scale;
  if (info_.reprojected) {
    QuietGdal quiet;
    TransformPtr t = FileMeshTransform(info_, /*to_mesh=*/true);
    if (t == nullptr || !t->Transform(1, &mx, &my)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": cannot project it (", QuietGdal::LastMessage(), ")"));
    }
  }
  return DropMeshPoint(mx, my, u, v, name);
}

absl::StatusOr<SurfacePoint> Dem::DropLonLat(double lon, double lat) const {
  const std::string name = absl::StrCat("ll:", Shortest(lon), ":", Shortest(lat));
  if (!(std::abs(lon) <= 180 && std::abs(lat) <= 90)) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": longitude must be in [-180, 180] and latitude in [-90, 90]"));
  }
  QuietGdal quiet;
  TransformPtr t = Wgs84Transform(info_, /*from_wgs84=*/true);
  double x = lon, y = lat;
  if (t == nullptr || !t->Transform(1, &x, &y)) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": cannot project it to the DEM's CRS (",
                                                   QuietGdal::LastMessage(), ")"));
  }
  LongitudesToGrid(info_, &x, 1);
  absl::StatusOr<SurfacePoint> p = DropNamed(x, y, name);
  if (!OutsideTheDem(p.status())) return p;
  std::string message(p.status().message());
  if (absl::StatusOr<std::array<double, 4>> box = LonLatExtent(); box.ok()) {
    absl::StrAppendFormat(&message, " (it covers longitude %.8g to %.8g, latitude %.8g to %.8g)",
                          (*box)[0], (*box)[2], (*box)[1], (*box)[3]);
  }
  double sx = lat, sy = lon;  // longitude and latitude the other way round
  if (std::abs(lat) <= 180 && std::abs(lon) <= 90 && t->Transform(1, &sx, &sy)) {
    LongitudesToGrid(info_, &sx, 1);
    if (InGrid(sx, sy)) {
      absl::StrAppend(&message, "; ll:", Shortest(lat), ":", Shortest(lon),
                      " would be inside (longitude first: ll:LON:LAT)");
    }
  }
  return absl::InvalidArgumentError(message);
}

absl::StatusOr<SurfacePoint> Dem::DropMeshPoint(double mx, double my, double u, double v,
                                                const std::string& name) const {
  const uint32_t W = info_.grid_width, H = info_.grid_height;
  constexpr double kEdge = 1e-9;  // grid units: a point on the outer boundary is inside
  if (!(u >= -kEdge && u <= W - 1 + kEdge && v >= -kEdge && v <= H - 1 + kEdge)) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": outside the DEM"));
  }
  if (is_tin()) return DropOnTin(mx, my, u, v, name);
  const int bi = std::clamp(static_cast<int>(std::floor(u)), 0, static_cast<int>(W) - 2);
  const int bj = std::clamp(static_cast<int>(std::floor(v)), 0, static_cast<int>(H) - 2);
  // The point's block and its neighbours: a point on a grid line belongs to two blocks (one may be
  // a hole), and a reprojected grid is not exactly affine. The face holding it best wins.
  uint32_t best_face = kNoVertex;
  std::array<double, 3> best{};
  double best_min = -std::numeric_limits<double>::infinity();
  for (int dj = 0; dj <= 2; ++dj) {
    for (int di = 0; di <= 2; ++di) {
      const int i = bi + (di == 2   ? -1
                          : di == 1 ? 1
                                    : 0),
                j = bj + (dj == 2   ? -1
                          : dj == 1 ? 1
                                    : 0);
      if (i < 0 || j < 0 || i > static_cast<int>(W) - 2 || j > static_cast<int>(H) - 2) continue;
      for (int k = 0; k < 2; ++k) {
        const uint64_t triangle = 2 * (uint64_t(j) * (W - 1) + i) + k;
        // The block triangle's face, or the pieces a barrier cut left of it.
        std::vector<uint32_t> candidates;
        if (face_of_block_[triangle] != kNoVertex) candidates.push_back(face_of_block_[triangle]);
        for (auto it = std::lower_bound(pieces_.begin(), pieces_.end(),
                                        std::make_pair(triangle, uint32_t{0}));
             it != pieces_.end() && it->first == triangle; ++it) {
          candidates.push_back(it->second);
        }
        for (const uint32_t f : candidates) {
          const double* p[3];
          for (int c = 0; c < 3; ++c)
            p[c] = &mesh_.positions[3 * size_t{mesh_.faces[3 * size_t{f} + c]}];
          // Barycentrics of (mx, my) in the face's projection onto the map plane.
          const double det =
              (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
          if (det == 0) continue;
          const double b1 =
              ((mx - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (my - p[0][1])) / det;
          const double b2 =
              ((p[1][0] - p[0][0]) * (my - p[0][1]) - (mx - p[0][0]) * (p[1][1] - p[0][1])) / det;
          const std::array<double, 3> b = {1 - b1 - b2, b1, b2};
          const double lowest = std::min({b[0], b[1], b[2]});
          if (lowest > best_min) {
            best_min = lowest;
            best = b;
            best_face = f;
          }
        }
      }
    }
  }
  if (best_face == kNoVertex || best_min < -1e-7) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": in a hole of the DEM (nodata or a barrier)"));
  }
  double sum = 0;
  for (double& b : best) sum += (b = b > 0 ? b : 0.0);  // also turns -0 into 0
  return SurfacePoint::InFace(best_face, best[0] / sum, best[1] / sum, best[2] / sum);
}

namespace {

// One band on the used grid, made in memory and copied out by the format the path's extension
// names (GisFormatOf); `value_of_cell` gives each cell's value (row-major index), kRasterNoSurface
// (the band's nodata) where there is no surface.
absl::Status WriteRaster(const DemInfo& info, const std::string& path, GDALDataType type,
                         const char* description, const char* unit,
                         const std::function<double(size_t)>& value_of_cell) {
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
      cells.travel_time ? "s" : "m", [&](size_t cell) {
        if (cells.hole[cell]) return kRasterNoSurface;
        const double d = cells.distance[cell];
        return std::isfinite(d) ? d : kRasterUnreachable;
      });
}

absl::Status Dem::WriteLabelRaster(const std::string& path, const CellValues& cells) const {
  if (cells.source.size() != size_t{info_.grid_width} * info_.grid_height) {
    return absl::InternalError("one value per used cell expected");
  }
  return WriteRaster(info_, path, GDT_Int32, "nearest source", nullptr, [&](size_t cell) {
    if (cells.hole[cell]) return kRasterNoSurface;
    const uint32_t s = cells.source[cell];
    return s >= 0x80000000u ? kRasterUnreachable : static_cast<double>(s);
  });
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

// ---------------------------------------------------------------------------------------------
// Friction (geodex/friction.h): beside the barrier reader, whose file and GeoJSON rules it shares.

namespace {

// Each face's centroid in the DEM file's CRS (`dem`), or in the mesh's x y (no `dem`).
absl::StatusOr<std::vector<std::array<double, 2>>> FaceCentresInMap(const MeshData& mesh,
                                                                    const DemInfo* dem,
                                                                    const std::string& name) {
  const size_t nf = mesh.faces.size() / 3;
  std::vector<double> xs(nf), ys(nf);
  for (size_t f = 0; f < nf; ++f) {
    double x = 0, y = 0;
    for (int k = 0; k < 3; ++k) {
      x += mesh.positions[3 * size_t{mesh.faces[3 * f + k]}] / 3;
      y += mesh.positions[3 * size_t{mesh.faces[3 * f + k]} + 1] / 3;
    }
    xs[f] = x;
    ys[f] = y;
  }
  if (dem != nullptr && dem->reprojected) {
    TransformPtr back = FileMeshTransform(*dem, /*to_mesh=*/false);
    std::vector<int> ok(nf);
    if (back == nullptr ||
        (nf > 0 &&
         !back->Transform(static_cast<int>(nf), xs.data(), ys.data(), nullptr, ok.data())) ||
        std::find(ok.begin(), ok.end(), 0) != ok.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": the faces do not project back to the DEM's CRS"));
    }
    LongitudesToGrid(*dem, xs.data(), nf);
  } else if (dem != nullptr) {
    for (size_t f = 0; f < nf; ++f) {
      xs[f] /= dem->horizontal_scale;
      ys[f] /= dem->horizontal_scale;
    }
  }
  std::vector<std::array<double, 2>> out(nf);
  for (size_t f = 0; f < nf; ++f) out[f] = {xs[f], ys[f]};
  return out;
}

// Points bucketed on a uniform grid over their bounding box (counting sort: flat arrays).
class CentreGrid {
 public:
  explicit CentreGrid(const std::vector<std::array<double, 2>>& points) : points_(points) {
    if (points.empty()) return;
    min_x_ = max_x_ = points[0][0];
    min_y_ = max_y_ = points[0][1];
    for (const auto& [x, y] : points) {
      min_x_ = std::min(min_x_, x);
      max_x_ = std::max(max_x_, x);
      min_y_ = std::min(min_y_, y);
      max_y_ = std::max(max_y_, y);
    }
    side_ = std::max<size_t>(1, static_cast<size_t>(std::sqrt(points.size() / 4.0)));
    start_.assign(side_ * side_ + 1, 0);
    for (const auto& [x, y] : points) ++start_[Cell(x, y) + 1];
    for (size_t c = 0; c < side_ * side_; ++c) start_[c + 1] += start_[c];
    order_.resize(points.size());
    std::vector<uint32_t> at(start_.begin(), start_.end() - 1);
    for (uint32_t i = 0; i < points.size(); ++i) {
      order_[at[Cell(points[i][0], points[i][1])]++] = i;
    }
  }

  // The points of every cell the box [x0, x1] x [y0, y1] touches (a superset of those inside).
  std::vector<uint32_t> Near(double x0, double y0, double x1, double y1) const {
    std::vector<uint32_t> out;
    if (points_.empty() || x1 < min_x_ || x0 > max_x_ || y1 < min_y_ || y0 > max_y_) return out;
    const size_t i0 = Index(x0, min_x_, max_x_), i1 = Index(x1, min_x_, max_x_);
    const size_t j0 = Index(y0, min_y_, max_y_), j1 = Index(y1, min_y_, max_y_);
    for (size_t j = j0; j <= j1; ++j) {
      for (size_t i = i0; i <= i1; ++i) {
        const size_t c = j * side_ + i;
        out.insert(out.end(), order_.begin() + start_[c], order_.begin() + start_[c + 1]);
      }
    }
    return out;
  }

 private:
  size_t Index(double v, double lo, double hi) const {
    if (!(hi > lo)) return 0;
    const double at = (v - lo) / (hi - lo) * side_;
    return at <= 0 ? 0 : std::min(side_ - 1, static_cast<size_t>(at));
  }
  size_t Cell(double x, double y) const {
    return Index(y, min_y_, max_y_) * side_ + Index(x, min_x_, max_x_);
  }

  const std::vector<std::array<double, 2>>& points_;
  double min_x_ = 0, max_x_ = 0, min_y_ = 0, max_y_ = 0;
  size_t side_ = 1;
  std::vector<uint32_t> start_, order_;
};

// Each face's friction: the largest of the regions (in the DEM file's CRS, or the mesh's own x y
// without a DEM) containing its centroid, 1 elsewhere. A reprojected DEM's faces are classified
// in the mesh's CRS, the polygons projected there vertex by vertex as CutOutlines projects them,
// so that a face of a mesh cut along their outlines lies on one side.
absl::StatusOr<std::vector<double>> FaceFrictionOf(std::vector<FrictionRegion> regions,
                                                   const MeshData& mesh, const DemInfo* dem,
                                                   const std::string& name) {
  const bool in_mesh_crs = dem != nullptr && dem->reprojected;
  if (in_mesh_crs) {
    TransformPtr to_mesh = FileMeshTransform(*dem, /*to_mesh=*/true);
    if (to_mesh == nullptr) {
      return absl::InvalidArgumentError(absl::StrCat(
          name, ": cannot project it to the mesh's CRS (", QuietGdal::LastMessage(), ")"));
    }
    for (FrictionRegion& r : regions) {
      if (r.shape->transform(to_mesh.get()) != OGRERR_NONE) {
        return absl::InvalidArgumentError(absl::StrCat(
            name, ": cannot project a polygon to the mesh's CRS (", QuietGdal::LastMessage(), ")"));
      }
    }
  }
  std::vector<OGREnvelope> boxes(regions.size());
  for (size_t i = 0; i < regions.size(); ++i) regions[i].shape->getEnvelope(&boxes[i]);
  absl::StatusOr<std::vector<std::array<double, 2>>> centres =
      FaceCentresInMap(mesh, in_mesh_crs ? nullptr : dem, name);
  if (!centres.ok()) return centres.status();
  std::vector<double> weight(centres->size(), 1.0);
  std::vector<char> inside_any(centres->size(), 0);
  // The centres bucketed on a grid of about 4 per cell, so a polygon visits only the faces near
  // its box: the cost grows with faces + polygons + the faces inside boxes, not faces x polygons
  // (a land-cover layer has thousands of polygons, a DEM a million faces).
  const CentreGrid grid(*centres);
  OGRPoint point;
  for (size_t i = 0; i < regions.size(); ++i) {
    const FrictionRegion& r = regions[i];
    const OGREnvelope& box = boxes[i];
    for (const uint32_t f : grid.Near(box.MinX, box.MinY, box.MaxX, box.MaxY)) {
      const auto& [x, y] = (*centres)[f];
      if (x < box.MinX || x > box.MaxX || y < box.MinY || y > box.MaxY) continue;
      point.setX(x);
      point.setY(y);
      bool inside = false;
      if (const OGRPolygon* p = dynamic_cast<const OGRPolygon*>(r.shape.get())) {
        inside = p->IsPointOnSurface(&point);
      } else if (const auto* m = dynamic_cast<const OGRMultiPolygon*>(r.shape.get())) {
        for (const OGRPolygon* part : *m) inside = inside || part->IsPointOnSurface(&point);
      }
      if (!inside) continue;
      weight[f] = inside_any[f] ? std::max(weight[f], r.friction) : r.friction;
      inside_any[f] = 1;
    }
  }
  return weight;
}

}  // namespace

absl::StatusOr<std::vector<double>> FrictionFromGeoJson(const MeshData& mesh,
                                                        const std::string& geojson,
                                                        const DemInfo* dem,
                                                        const std::string& name) {
  QuietGdal quiet;
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(dem, name, &file_crs); !s.ok()) return s;
  return WithGeoJsonText<std::vector<double>>(
      geojson, name, [&](GDALDataset& ds) -> absl::StatusOr<std::vector<double>> {
        absl::StatusOr<std::vector<FrictionRegion>> regions =
            ReadFrictionRegions(ds, dem != nullptr ? &file_crs : nullptr, name);
        if (!regions.ok()) return regions.status();
        return FaceFrictionOf(*std::move(regions), mesh, dem, name);
      });
}

absl::StatusOr<MeshData> CutFrictionOutlines(const MeshData& mesh, const std::string& geojson,
                                             const DemInfo* dem, const std::string& name,
                                             CutStats* stats, uint64_t max_vertices) {
  QuietGdal quiet;
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(dem, name, &file_crs); !s.ok()) return s;
  return WithGeoJsonText<MeshData>(geojson, name, [&](GDALDataset& ds) -> absl::StatusOr<MeshData> {
    // Read and checked as FrictionFromGeoJson reads them: a bad value fails here too.
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(ds, dem != nullptr ? &file_crs : nullptr, name);
    if (!regions.ok()) return regions.status();
    return CutOutlines(mesh, *OutlinesOf(*regions), dem, &file_crs, max_vertices, name, stats);
  });
}

absl::StatusOr<std::vector<double>> ReadFrictionFiles(const MeshData& mesh,
                                                      const std::vector<std::string>& paths,
                                                      const DemInfo& dem) {
  if (paths.size() == 1) return ReadFrictionFile(mesh, paths[0], dem, "--friction " + paths[0]);
  QuietGdal quiet;
  const std::string names = FlagFilesName("friction", paths);
  for (const std::string& path : paths) {
    const std::string name = absl::StrCat("--friction ", path);
    const GisFormat* format = GisFormatOf(path);
    if (format != nullptr && format->kind == GisFileKind::kRaster) {
      return absl::InvalidArgumentError(absl::StrCat(
          name,
          ": a friction raster is given alone (it values every face); only polygon files "
          "add up when --friction is repeated"));
    }
  }
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(&dem, names, &file_crs); !s.ok()) return s;
  // Every file's polygons in one list: as one file holding them all (overlaps take the largest).
  std::vector<FrictionRegion> all;
  for (const std::string& path : paths) {
    const std::string name = absl::StrCat("--friction ", path);
    absl::StatusOr<GDALDatasetUniquePtr> ds = OpenBarrierFile(path, name);
    if (!ds.ok()) return ds.status();
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(**ds, &file_crs, name);
    if (!regions.ok()) return regions.status();
    for (FrictionRegion& r : *regions) all.push_back(std::move(r));
  }
  return FaceFrictionOf(std::move(all), mesh, &dem, names);
}

absl::StatusOr<std::vector<double>> ReadFrictionFile(const MeshData& mesh, const std::string& path,
                                                     const DemInfo& dem, const std::string& name) {
  QuietGdal quiet;
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
  };
  OGRSpatialReference file_crs;
  if (absl::Status s = ParseFileCrs(&dem, name, &file_crs); !s.ok()) return s;
  const GisFormat* format = GisFormatOf(path);
  if (format == nullptr || format->kind != GisFileKind::kRaster) {  // polygons
    absl::StatusOr<GDALDatasetUniquePtr> ds = OpenBarrierFile(path, name);
    if (!ds.ok()) return ds.status();
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(**ds, &file_crs, name);
    if (!regions.ok()) return regions.status();
    return FaceFrictionOf(*std::move(regions), mesh, &dem, name);
  }
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return absl::NotFoundError(absl::StrCat(name, ": cannot open: No such file or directory"));
  }
  // A raster: the drivers and side-car rules of Dem::Read.
  GDALDatasetUniquePtr ds = OpenUserRaster(path);
  if (ds == nullptr) {
    return bad(absl::StrCat("not a raster GDAL reads (", QuietGdal::LastMessage(), ")"));
  }
  if (ds->GetRasterCount() != 1) return bad("a friction raster has one band");
  const OGRSpatialReference* crs = ds->GetSpatialRef();
  if (crs == nullptr || crs->IsEmpty()) return bad("no coordinate reference system");
  if (std::string why = InconsistentCrsId(*crs); !why.empty()) return bad(why);
  if (!crs->IsSame(&file_crs)) {
    return bad(absl::StrCat("its CRS (", crs->GetName() != nullptr ? crs->GetName() : "?",
                            ") is not the DEM's (", dem.file_crs_name,
                            "); reproject it first (gdalwarp -t_srs)"));
  }
  double gt[6];
  if (ds->GetGeoTransform(gt) != CE_None || gt[2] != 0 || gt[4] != 0 || gt[1] == 0 || gt[5] == 0 ||
      !std::all_of(gt, gt + 6, [](double v) { return std::isfinite(v); })) {
    return bad("no north-up geotransform");
  }
  const int W = ds->GetRasterXSize(), H = ds->GetRasterYSize();
  if (int64_t{W} * H > (int64_t{1} << 28)) {
    return bad(absl::StrFormat("%dx%d cells: more than a friction raster may have (2^28)", W, H));
  }
  absl::StatusOr<std::vector<std::array<double, 2>>> centres = FaceCentresInMap(mesh, &dem, name);
  if (!centres.ok()) return centres.status();
  GDALRasterBand* band = ds->GetRasterBand(1);
  std::vector<double> cells(size_t(W) * H);
  if (band->RasterIO(GF_Read, 0, 0, W, H, cells.data(), W, H, GDT_Float64, 0, 0) != CE_None) {
    return bad(absl::StrCat("cannot read its cells (", QuietGdal::LastMessage(), ")"));
  }
  int has_nodata = 0;
  const double nodata = band->GetNoDataValue(&has_nodata);
  std::vector<double> weight(centres->size());
  for (size_t f = 0; f < centres->size(); ++f) {
    const auto& [x, y] = (*centres)[f];
    const double u = std::floor((x - gt[0]) / gt[1]), v = std::floor((y - gt[3]) / gt[5]);
    if (!(u >= 0 && v >= 0 && u < W && v < H)) {
      return bad(absl::StrFormat(
          "it does not cover the DEM: face %d's centre (%.10g, %.10g) is outside it", f, x, y));
    }
    const double value = cells[static_cast<size_t>(v) * W + static_cast<size_t>(u)];
    if ((has_nodata && value == nodata) || std::isnan(value)) {
      weight[f] = std::numeric_limits<double>::infinity();  // no data: impassable
    } else if (!(value > 0)) {
      return bad(absl::StrFormat("cell (column %d, row %d) has friction %g; it must be > 0",
                                 static_cast<int>(u), static_cast<int>(v), value));
    } else {
      weight[f] = value;
    }
  }
  return weight;
}

}  // namespace geodex::terrain
