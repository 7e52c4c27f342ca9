#pragma once

// GeoJSON (RFC 7946) out of a DEM's results, written by GDAL's GeoJSON driver: WGS 84 longitude/
// latitude with right-hand-rule rings by default; with `native_crs`, the DEM's own CRS (named in
// the file's "crs" member, which RFC 7946 leaves out). Polygons are the union (GEOS, through GDAL)
// of pieces in the mesh's metric plane, so each is valid (no self-intersection, holes as rings).

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/delaunay.h"
#include "geodex/gis_formats.h"
#include "geodex/mesh_data.h"
#include "geodex/shortest_path.h"
#include "geodex/terrain.h"
#include "geodex/travel_cost.h"
#include "geodex/voronoi.h"

namespace geodex::terrain {

using Polygon2 = std::vector<std::array<double, 2>>;  // one ring, mesh x y (not closed)
// A property's value; std::monostate is JSON null (written as null, not left out).
using Property =
    std::pair<std::string, std::variant<std::monostate, double, int64_t, std::string, bool>>;

struct GeoFeature {
  enum class Kind { kArea, kLine, kPoint };
  Kind kind = Kind::kPoint;
  std::vector<Polygon2> pieces;  // kArea: their union is the feature's (Multi)Polygon
  // kArea: the pieces tile their union exactly (neighbours share edges bit for bit, each piece
  // counter-clockwise, as SublevelPieces makes them): the union is built from the unshared edges
  // alone, in time linear in the pieces, instead of by a general polygon union.
  bool exact_tiling = false;
  std::vector<std::array<double, 3>>
      points;  // kLine (3D LineString), kPoint (one 3D point); mesh x y z
  std::vector<Property> properties;
};

// Writes `features` as one layer, in the vector format the path's extension names (gis_formats.h:
// .geojson, .gpkg, .shp, .fgb). GeoJSON is RFC 7946 (WGS 84) unless `native_crs`; every other
// format is in the DEM's CRS. Errors name the path (with GDAL's reason); an extension that is not a
// vector format's is InvalidArgument listing them.
// `provenance` (gis_formats.h), when given, is recorded: GeoJSON's "geodex" member, other formats'
// layer metadata.
absl::Status WriteVectorFile(const DemInfo& dem, const std::vector<GeoFeature>& features,
                             const std::string& path, bool native_crs,
                             const Provenance* provenance = nullptr);
// The same file's text (what geodexd's ExportGis sends).
absl::StatusOr<std::string> GeoJsonText(const DemInfo& dem, const std::vector<GeoFeature>& features,
                                        bool native_crs, const Provenance* provenance = nullptr);

// The features of each product, as the CLI and geodexd write them; x y z in the DEM's mesh.
// Isochrones: per level, the area within that distance (`level`, `units` "m"), from the field's
// vertex values on `mesh`. A travel-cost field (`travel` non-null, geodex/travel_cost.h): levels
// are times (`units` "s") and each feature says how they were made, as JSON answers do:
// `epsilon`, `bound` (true: within (1 + epsilon) of the least time; false for a slope speed, which
// has no proven bound), `speed` ("constant", "tobler", "table") and `inbound`.
std::vector<GeoFeature> IsochroneFeatures(const MeshData& mesh, const std::vector<double>& distance,
                                          const std::vector<double>& levels,
                                          const TravelCost* travel = nullptr);
// Voronoi cells: one (Multi)Polygon per site (`site`, `area`), its whole faces and fragments.
std::vector<GeoFeature> VoronoiFeatures(const MeshData& mesh, const VoronoiDiagram& diagram);
// Delaunay edges: one 3D LineString per edge (`site_a`, `site_b`, `length`).
std::vector<GeoFeature> DelaunayFeatures(const DelaunayTriangulation& delaunay);
// A path: one 3D LineString with its length along the surface in metres (`length_m`; also as
// `length` with `units` "m") and, for a travel-cost path (`time_s` finite), its time in seconds
// (`time_s`): seconds are never labelled as metres.
GeoFeature PathFeature(const std::vector<PathPoint>& points, double length_m,
                       double time_s = std::numeric_limits<double>::quiet_NaN());
// Points with their distance: `point` as the user wrote it, `surface_point` where it landed,
// `distance` and `source` (both null where the point is unreachable).
struct PointValue {
  std::array<double, 3> position{};
  std::string point, surface_point;
  double distance = 0;
  int64_t source = -1;
};
// With `travel` (the values are travel times) each point's value is `time_s` with `units` "s",
// else `distance` with `units` "m": a value always says what it is.
std::vector<GeoFeature> PointFeatures(const std::vector<PointValue>& points,
                                      const TravelCost* travel = nullptr);

// The part of each face where the field, linear on the face between its vertices' values, is at
// most `level`: a convex polygon per face (an edge to a vertex at +inf contributes only its finite
// end). In the mesh's x y: what an isochrone polygon is the union of. `value` is per file vertex
// (a DistanceField's `distance`): where fans of faces meet at one vertex only (a nodata corner),
// every fan sees that vertex's smallest value, a small approximation next to such vertices.
std::vector<Polygon2> SublevelPieces(const MeshData& mesh, const std::vector<double>& value,
                                     double level);

}  // namespace geodex::terrain
