#pragma once

// Every GIS file geodex writes, chosen by the output path's extension: the one table of extension
// to GDAL/OGR driver (terrain/src/gis_formats.cc). Rasters are written on the DEM's grid, vectors
// in WGS 84 for GeoJSON (RFC 7946) and in the DEM's own CRS otherwise.

#include <string>
#include <utility>
#include <vector>

#include "geodex/geodesic_solver.h"

namespace geodex::terrain {

// What made a GIS file, recorded in it (docs/gis-files.md): a raster's metadata items GEODEX_KEY
// (gdalinfo lists them; the software also as TIFFTAG_SOFTWARE), a GeoJSON's "geodex" member, the
// layer metadata GEODEX_KEY of other vector formats. Never a clock time: the same inputs make the
// same bytes.
struct Provenance {
  std::vector<std::pair<std::string, std::string>> items;  // (key, value), in order
};
// software ("geodex VERSION"), made_by (the command line, or the request), then what the values
// are with `options` (values, units; a travel cost's speed, epsilon, exact and bound; lambda).
Provenance MakeProvenance(const std::string& made_by, const GeodesicOptions* options);
// The items as a JSON object's text (the GeoJSON member).
std::string ProvenanceJson(const Provenance& provenance);
// `text` as a JSON string literal (RFC 8259 escapes): the one quoting of geodex's JSON, the CLI's
// included.
std::string JsonQuoted(const std::string& text);

enum class GisFileKind { kRaster, kVector };

struct GisFormat {
  const char* extension;  // lower case, with its dot
  const char* driver;     // GDAL's short name
  GisFileKind kind;
  const char* description;
};

// The format of `path` by its extension (any case), or null when it is not a GIS file's.
const GisFormat* GisFormatOf(const std::string& path);
// True for an extension some GDAL driver reads or writes that is not in the table (nor plain text
// the CLI writes itself: .txt, .csv, .json, ...): `--output x.img` is refused, not written as text.
bool IsOtherGisExtension(const std::string& path);
// Removes an earlier output at `path` (and a Shapefile's side-cars, an .aux.xml) by name.
void RemoveOldOutput(const std::string& path);
// The extensions of one kind, for messages: ".tif, .tiff, .asc, .nc".
std::string GisExtensions(GisFileKind kind);

// Raster values (docs/gis-files.md): a cell with no surface (nodata in the DEM, below
// --barrier-below, inside a barrier) is the band's nodata value; a cell on the surface that no
// path reaches (another part of the surface, beyond --max-distance) has its own value, so that
// both read apart in formats without a mask band.
inline constexpr double kRasterNoSurface = -1;
inline constexpr double kRasterUnreachable = -2;

}  // namespace geodex::terrain
