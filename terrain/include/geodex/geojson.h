#pragma once

// GeoJSON (RFC 7946) out of a DEM's results, written by GDAL's GeoJSON driver: WGS 84 longitude/
// latitude with right-hand-rule rings by default; with `native_crs`, the DEM's own CRS (named in
// the file's "crs" member, which RFC 7946 leaves out). Polygons are the union (GEOS, through GDAL)
// of pieces in the mesh's metric plane, so each is valid (no self-intersection, holes as rings).

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "absl/status/status.h"
#include "geodex/mesh_data.h"
#include "geodex/terrain.h"

namespace geodex::terrain {

using Polygon2 = std::vector<std::array<double, 2>>;  // one ring, mesh x y (not closed)
using Property = std::pair<std::string, std::variant<double, int64_t, std::string>>;

struct GeoFeature {
  enum class Kind { kArea, kLine, kPoint };
  Kind kind = Kind::kPoint;
  std::vector<Polygon2> pieces;              // kArea: their union is the feature's (Multi)Polygon
  // kArea: the pieces tile their union exactly (neighbours share edges bit for bit, each piece
  // counter-clockwise, as SublevelPieces makes them): the union is built from the unshared edges
  // alone, in time linear in the pieces, instead of by a general polygon union.
  bool exact_tiling = false;
  std::vector<std::array<double, 3>> points; // kLine (3D LineString), kPoint (one 3D point); mesh x y z
  std::vector<Property> properties;
};

// Writes `features` as one FeatureCollection. Errors name the path (with GDAL's reason).
absl::Status WriteGeoJson(const DemInfo& dem, const std::vector<GeoFeature>& features,
                          const std::string& path, bool native_crs);

// The part of each face where the field, linear on the face between its vertices' values, is at
// most `level`: a convex polygon per face (an edge to a vertex at +inf contributes only its finite
// end). In the mesh's x y: what an isochrone polygon is the union of. `value` is per file vertex
// (a DistanceField's `distance`): where fans of faces meet at one vertex only (a nodata corner),
// every fan sees that vertex's smallest value, a small approximation next to such vertices.
std::vector<Polygon2> SublevelPieces(const MeshData& mesh, const std::vector<double>& value,
                                     double level);

}  // namespace geodex::terrain
