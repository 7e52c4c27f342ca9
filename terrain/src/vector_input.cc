// Vector input for barriers, friction polygons and point files (dem_internal.h): a layer's
// transform to the DEM's CRS, GeoJSON's "crs" members checked (identifiers only: no URL or file is
// followed), a local file's side-cars listed, and the vector files a user names opened, each
// through its own driver. (GeoJSON text from a client: WithGeoJsonText, in dem_internal.h.)

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <system_error>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "cpl_json.h"
#include "cpl_string.h"
#include "dem_internal.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"

namespace geodex::terrain::dem_internal {

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

}  // namespace

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

}  // namespace geodex::terrain::dem_internal
