#pragma once

// Friction for travel cost (geodex/travel_cost.h): one multiplicative weight per face of a mesh,
// from what GIS users draw or already have. Read under the same rules as barriers (no file or URL a
// file names is opened; GeoJSON names its CRS only by an identifier); defined in friction.cc,
// sharing the barrier reader's helpers (dem_internal.h).

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"
#include "geodex/terrain.h"

namespace geodex::terrain {

// Friction polygons: `geojson` is the text of a GeoJSON FeatureCollection (or Feature) of Polygons
// and MultiPolygons, each with a numeric property "friction" (> 0; a barrier is better drawn as
// one, but "inf" or a huge value works too), RFC 7946 WGS 84 unless it names its CRS, on a DEM's
// mesh (`dem`: its map), or with `dem` null in the mesh's own x y. Each face takes the friction of
// the polygon containing its centroid (the largest where polygons overlap) and 1 elsewhere: on a
// mesh cut along the polygons' outlines (CutFrictionOutlines, DemOptions::friction_file) region
// boundaries are exact, on any other as fine as the mesh. InvalidArgument starting with `name` for
// text that is not GeoJSON polygons, a feature without a positive numeric friction, a polygon
// that cannot be used as drawn (a coordinate not finite or beyond 1e12, a ring of fewer than 3
// distinct points, or invalid and enclosing no area once repaired: it names the feature), or
// polygons that do not project to the mesh's CRS. Nothing is dropped in silence.
absl::StatusOr<std::vector<double>> FrictionFromGeoJson(const MeshData& mesh,
                                                        const std::string& geojson,
                                                        const DemInfo* dem,
                                                        const std::string& name);

// The friction polygons' outlines (GeoJSON text as FrictionFromGeoJson's, checked the same way)
// cut into `mesh`: every face an outline crosses is split along it, nothing is removed, vertices
// keep their ids and new ones follow (a DEM's polygons are projected to its mesh's CRS vertex by
// vertex: edges straight there). FrictionFromGeoJson with the same text on the result gives each
// region its value up to its boundary. `max_vertices` and the errors as CutBarrierPolygons.
absl::StatusOr<MeshData> CutFrictionOutlines(const MeshData& mesh, const std::string& geojson,
                                             const DemInfo* dem, const std::string& name,
                                             CutStats* stats, uint64_t max_vertices = 0);

// A friction file for a DEM's mesh: GeoJSON polygons as above (a .geojson or .json path), or a
// one-band raster GDAL reads (.tif, ...) in the DEM's CRS: each face takes the value of the cell
// under its centroid; nodata is impassable (+inf). InvalidArgument starting with `name` for a
// raster in another CRS, one not covering every face's centroid, or a value <= 0 (the cell named).
absl::StatusOr<std::vector<double>> ReadFrictionFile(const MeshData& mesh, const std::string& path,
                                                     const DemInfo& dem, const std::string& name);
// Several --friction files: polygon files add up, read as one file holding every polygon (where
// polygons overlap, the largest friction); a raster must come alone (InvalidArgument naming it).
// One path is ReadFrictionFile's, named "--friction PATH".
absl::StatusOr<std::vector<double>> ReadFrictionFiles(const MeshData& mesh,
                                                      const std::vector<std::string>& paths,
                                                      const DemInfo& dem);

}  // namespace geodex::terrain
