#pragma once

// Terrain input: a digital elevation model (any single-band raster GDAL reads; GeoTIFF first) as
// a triangle mesh in metres, with the map it came from.
//
// The mesh: each used cell centre is a vertex (every `step`-th cell in each direction), each 2x2
// block of used cells two triangles split along the same diagonal, a triangle only where its
// three cells have data (nodata cells leave holes with their own boundaries). Vertices are
// numbered row by row, skipping nodata cells; faces block by block.
//
// Coordinates: a projected CRS is used as is (its linear unit converted to metres); a geographic
// CRS (longitude/latitude) is projected to the UTM zone of the DEM's centre (WGS 84 datum), so
// every distance is in metres. Heights are converted to metres from the band's unit ("m", "ft",
// "US survey foot"; none given: metres).
//
// An adaptive TIN (DemOptions::z_tolerance > 0): instead of every used cell, the few cells a
// greedy insertion needs for the surface to lie within Z of every used cell's height (Garland and
// Heckbert; adaptive_tin.h), Delaunay-triangulated in the grid's plane. Its vertices are cell
// centres (row order, as the grid's); its faces are large. Map points drop onto its faces, and
// rasters (on the used grid as ever) take at each cell the value at the TIN's point below the
// cell's centre (SampleCells).

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/cancel.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/gis_formats.h"
#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

class GDALDataset;
class OGRSpatialReference;

namespace geodex::terrain {

struct DemOptions {
  uint32_t step = 1;  // use every step-th cell (a quick look at a large DEM)
  // A barrier: cells lower than this (metres; the sea at 0) are left out like nodata, so paths
  // go around them. -inf: none.
  double barrier_below = -std::numeric_limits<double>::infinity();
  // Barriers drawn as polygons (GeoJSON, Shapefile, GeoPackage or FlatGeobuf; each its own CRS,
  // WGS 84 when it names none), cut exactly out of the surface (CutBarrierPolygons). Several files
  // add up: they cut what one file holding all their features cuts. Empty: none.
  std::vector<std::string> barrier_files;
  // The width (metres) of the lines and points in barrier_files; 0: lines are slits, points
  // refused.
  double barrier_width = 0;
  // Friction polygons (a vector file as barrier_files', each with a "friction" property): their
  // outlines are cut into the surface, nothing removed, so that each face lies in one region and
  // the friction read from the same file on this mesh (ReadFrictionFile) has exact region
  // boundaries (geodex/friction.h). "": none.
  std::string friction_file;
  // With friction_file: outlines snapped onto the mesh's vertices before they are cut in. A
  // vertex v within friction_snap x the shortest x-y edge at v of an outline is put on it (an
  // outline corner moved there, or v inserted into the outline's segment), so outlines leave no
  // sliver at v; the drawn boundary moves by at most that distance (docs/travel.md). 0: exact.
  // In [0, 0.25] (discs of neighbours stay apart).
  double friction_snap = 0;
  // The most cells (width x height of the file) a raster may have, and the most vertices and
  // faces its mesh may have (every used cell with data, two triangles per block); 0: any. What a
  // server sets before GDAL reads untrusted bytes: checked before any row is read, a
  // LimitExceededError (geodex/limits.h: kDemCells, kVertices, kFaces) above it.
  uint64_t max_cells = 0;
  // Stops an adaptive TIN's build (Cancelled) once cancelled; null: not cancellable.
  const CancelToken* cancel = nullptr;
  uint64_t max_vertices = 0;
  uint64_t max_faces = 0;
  // > 0: the mesh is an adaptive TIN whose surface is within this many of the band's height units
  // (converted to metres like the heights) of every used cell with data; 0: every used cell is a
  // vertex (the grid). Finite; negative is refused.
  double z_tolerance = 0;
};

// The faces of `mesh` with no corner lower than `z` (the same barrier on a mesh file: a face
// with a corner below it is removed; vertices keep their ids).
MeshData RemoveFacesBelow(const MeshData& mesh, double z);

// What a DEM mesh knows about its map.
// The one check of DemOptions' values (step in [1, 1000000], barrier_below not NaN, barrier_width
// finite and >= 0, z_tolerance finite and >= 0, friction_snap in [0, 0.25] and above 0 only with a
// friction_file to snap). InvalidArgument naming the option as core's errors do (InvalidOptionOf:
// "step", "barrier_below", "barrier_width", "z_tolerance", "friction_snap"), for the caller to
// put in its words: the CLI its flag (--dem-step, --z-tolerance, ...), geodexd its field
// (metadata.dem.z_tolerance). Dem::Read and ReadGeoTiffBytes check them too.
absl::Status ValidateDemOptions(const DemOptions& options);

struct DemInfo {
  std::string driver;                            // GDAL's short name ("GTiff")
  uint32_t raster_width = 0, raster_height = 0;  // the file's grid
  uint32_t step = 1;
  uint32_t grid_width = 0, grid_height = 0;  // the used cells
  uint64_t nodata_cells = 0;                 // used cells without data
  uint64_t barrier_cells = 0;                // used cells below DemOptions::barrier_below
  uint64_t barrier_faces = 0;                // grid triangles a barrier file removed or cut
  std::string file_crs_name;                 // the file's CRS ("WGS 84 / UTM zone 33N", "WGS 84")
  std::string file_crs_wkt;
  bool reprojected = false;   // the file's CRS is geographic: the mesh is in mesh_crs
  std::string mesh_crs_name;  // the CRS of the mesh's x and y (metres)
  std::string mesh_crs_wkt;
  double horizontal_scale = 1;  // file CRS units to metres (1 when reprojected)
  std::string vertical_unit;    // the band's unit as the file says it ("" = none given)
  double vertical_scale = 1;    // file heights to metres
  // The used grid's geotransform in the file's CRS (the file's own when step = 1): pixel (i, j)
  // has its corner at (gt[0] + i gt[1] + j gt[2], gt[3] + i gt[4] + j gt[5]).
  std::array<double, 6> geotransform{};
  // An adaptive TIN's (0 for the grid): DemOptions::z_tolerance, and the vertical distance between
  // the TIN and the used cells' heights (metres) measured at every used cell with data.
  double z_tolerance = 0;
  double max_vertical_deviation = 0;
  double rms_vertical_deviation = 0;

  bool operator==(const DemInfo&) const = default;
};

// What a barrier cut did to a mesh's faces.
struct CutStats {
  uint64_t faces_removed = 0;   // wholly inside a barrier
  uint64_t faces_cut = 0;       // partly inside: replaced by the pieces outside it
  uint64_t faces_split = 0;     // outside, split at points a neighbour's cut put on their edges
  uint64_t vertices_added = 0;  // where a barrier's edges cross the mesh, and its corners
};

// A barrier drawn as polygons, on any mesh: `geojson` is the text of a GeoJSON FeatureCollection,
// Feature or geometry (RFC 7946 WGS 84 unless it names its CRS) on a DEM's mesh (`dem`: its map),
// or, with `dem` null, polygons in the mesh's own x y (no CRS). The polygons are cut exactly out of
// the surface: what remains is the mesh minus the vertical prism over them, faces crossing a
// boundary split along it (see terrain/src/barrier_cut.h). Vertices keep their ids, new ones
// follow. InvalidArgument starting with `name` when the text is not GeoJSON polygons (or names
// its CRS by anything but an identifier). Only GDAL's GeoJSON driver reads it.
// Lines (LineString, MultiLineString) are slits with width 0 (both sides kept, paths go around
// their ends); with width > 0 they and points are walls that wide (metres in the mesh's plane,
// buffered with round ends). Points need a width.
// `max_vertices` (0: none) bounds the cut mesh: ResourceExhausted (geodex/limits.h kVertices)
// beyond it, checked as the cut goes (a barrier crossing many faces adds vertices at each).
absl::StatusOr<MeshData> CutBarrierPolygons(const MeshData& mesh, const std::string& geojson,
                                            const DemInfo* dem, double width,
                                            const std::string& name, CutStats* stats,
                                            uint64_t max_vertices = 0);
// Several GeoJSON texts, each named in its own errors: cut as one text holding all their features
// (the --barrier flag given several times). Errors about the cut itself name them all.
struct NamedText {
  std::string text;
  std::string name;
};
absl::StatusOr<MeshData> CutBarrierPolygons(const MeshData& mesh,
                                            const std::vector<NamedText>& geojsons,
                                            const DemInfo* dem, double width, CutStats* stats,
                                            uint64_t max_vertices = 0);
// "--barrier a.geojson, --barrier b.gpkg": how errors name several barrier files together.
std::string BarrierFilesName(const std::vector<std::string>& paths);

// A point read from a file (--sources-file, --targets-file): its coordinates in the file's CRS
// (crs_wkt; "" when the file names none: then in the DEM's CRS) and how messages name it.
struct FilePoint {
  double x = 0, y = 0;
  std::string crs_wkt;
  std::string name;  // "--sources-file pts.gpkg feature 3"
};
// Points (Point, MultiPoint) from a file the CLI's user names: GeoJSON (RFC 7946's WGS 84 unless
// its "crs" names another by an identifier), GeoPackage, Shapefile or FlatGeobuf (each its own
// driver only; their CRS, none: the DEM's), or CSV with x,y columns (the DEM's CRS) or lon,lat
// (WGS 84). InvalidArgument starting with `name` for anything else.
absl::StatusOr<std::vector<FilePoint>> ReadPointsFile(const std::string& path,
                                                      const std::string& name);
// The point as a SPEC item: ll:LON:LAT when its CRS is known, else g:X:Y.
absl::StatusOr<std::string> FilePointSpec(const FilePoint& point);

inline constexpr uint32_t kNoVertex = 0xffffffffu;

struct CellValues;  // below: a field's values at the used grid's cells

class Dem {
 public:
  // Errors: InvalidArgument naming the file (GDAL cannot read it, not one band, no CRS or
  // geotransform, a rotated grid, fewer than 2x2 used cells, an unknown height unit, no
  // triangle with data), NotFound when the file does not exist.
  static absl::StatusOr<Dem> Read(const std::string& path, const DemOptions& options = {});
  // The same from a GeoTIFF's bytes (an upload to geodexd; only GDAL's GTiff driver parses them,
  // and options.barrier_files must be empty). `name` spells the raster in errors.
  static absl::StatusOr<Dem> ReadGeoTiffBytes(const std::string& bytes, const std::string& name,
                                              const DemOptions& options = {});
  // A DEM mesh again from the mesh and its info, as stored by geodexd or fetched from it: each
  // vertex's cell is found from its position and each face's block from its corners.
  // InvalidArgument when the mesh is not such a DEM's (a vertex off the grid, out of row order,
  // a face that is not one of a block's two triangles).
  static absl::StatusOr<Dem> FromMesh(MeshData mesh, DemInfo info);

  Dem(Dem&&) noexcept;
  Dem& operator=(Dem&&) noexcept;
  ~Dem();

  const MeshData& mesh() const { return mesh_; }
  const DemInfo& info() const { return info_; }
  bool is_tin() const { return info_.z_tolerance > 0; }
  // Read with DemOptions::friction_file: each face's friction from the regions as they were cut in
  // (after DemOptions::friction_snap), 1 outside them. Empty otherwise.
  const std::vector<double>& face_friction() const { return face_friction_; }
  // The memory it holds (mesh copy and grid maps).
  uint64_t MemoryBytes() const {
    return mesh_.positions.capacity() * sizeof(double) +
           (mesh_.faces.capacity() + vertex_of_cell_.capacity() + face_of_block_.capacity() +
            face_of_cell_.capacity() + neighbours_.capacity()) *
               sizeof(uint32_t) +
           pieces_.capacity() * sizeof(pieces_[0]) + cell_uv_.capacity() * sizeof(cell_uv_[0]) +
           face_friction_.capacity() * sizeof(double);
  }
  // The vertex of used cell (col, row), or kNoVertex (nodata).
  uint32_t VertexAt(uint32_t col, uint32_t row) const {
    return vertex_of_cell_[size_t{row} * info_.grid_width + col];
  }

  // A map point dropped vertically onto the surface, as a face point: (x, y) in the file's CRS
  // (`g:X:Y`) or WGS 84 longitude/latitude (`ll:LON:LAT`). InvalidArgument naming the point when
  // it lies outside the used grid or in a hole (nodata or a barrier).
  // Outside the DEM, the message gives its extent in the point's own terms (x y in its CRS, or
  // longitude and latitude) and says when the point with its coordinates swapped would be inside.
  absl::StatusOr<SurfacePoint> DropMapPoint(double x, double y) const;
  absl::StatusOr<SurfacePoint> DropLonLat(double lon, double lat) const;
  // The used grid's cell centres in longitude/latitude: {lon min, lat min, lon max, lat max}.
  absl::StatusOr<std::array<double, 4>> LonLatExtent() const;
  // Whether (x, y) in the file's CRS lies within the used grid's cell centres.
  bool InGrid(double x, double y) const;

  // Writes one value per vertex as a single-band GeoTIFF aligned with the used grid (its
  // geotransform and the file's CRS): float32 with nodata -1 where a cell has no vertex or the
  // value is not finite (unreachable). Errors name the path (with the OS's reason).
  absl::Status WriteFloatRaster(const std::string& path, const std::vector<double>& values) const;
  // The same for indices (int32, nodata -1; kNoVertex-like values >= 2^31 are nodata).
  absl::Status WriteIndexRaster(const std::string& path, const std::vector<uint32_t>& values) const;
  // The same files' bytes (what geodexd's ExportGis sends).
  absl::StatusOr<std::string> FloatRasterBytes(const std::vector<double>& values) const;
  absl::StatusOr<std::string> IndexRasterBytes(const std::vector<uint32_t>& values) const;

  // The rasters of a field's values at the cells (SampleCells): float32 distances with nodata -1
  // where there is no surface and -2 where it is unreachable; int32 labels likewise.
  absl::Status WriteDistanceRaster(const std::string& path, const CellValues& cells) const;
  absl::Status WriteLabelRaster(const std::string& path, const CellValues& cells) const;
  absl::StatusOr<std::string> DistanceRasterBytes(const CellValues& cells) const;
  absl::StatusOr<std::string> LabelRasterBytes(const CellValues& cells) const;

  // The surface point below used cell (col, row)'s centre: its vertex on the grid (and on a TIN
  // when the cell is a vertex), else on a TIN a point of the face holding the centre. NotFound for
  // a cell in a hole (nodata, a barrier).
  absl::StatusOr<SurfacePoint> CellPoint(uint32_t col, uint32_t row) const;

 private:
  Dem() = default;
  // Read's work once GDAL has opened the raster (`name` spells it in errors).
  static absl::StatusOr<Dem> ReadDataset(GDALDataset& ds, const std::string& name,
                                         const DemOptions& options);
  // DropMapPoint, naming the point `name` in errors.
  absl::StatusOr<SurfacePoint> DropNamed(double x, double y, const std::string& name) const;
  // Drops a point given in the mesh's CRS (metres); `name` spells it in errors.
  absl::StatusOr<SurfacePoint> DropMeshPoint(double mx, double my, double u, double v,
                                             const std::string& name) const;

  MeshData mesh_;
  DemInfo info_;
  std::vector<uint32_t> vertex_of_cell_;  // grid_width * grid_height
  std::vector<uint32_t> face_of_block_;   // 2 per block ((grid_width-1) * (grid_height-1))
  // A barrier cut's faces: (block triangle, face), sorted; the triangle's face_of_block_ is then
  // kNoVertex.
  std::vector<std::pair<uint64_t, uint32_t>> pieces_;
  // An adaptive TIN's maps (empty on the grid): the face holding each used cell's centre
  // (kNoVertex in a hole), each face's neighbour across the edge opposite each corner (kNoVertex on
  // a boundary), and each vertex's (column, row) in cell units.
  std::vector<uint32_t> face_of_cell_;
  std::vector<uint32_t> neighbours_;
  std::vector<std::array<double, 2>> cell_uv_;
  std::vector<double> face_friction_;  // face_friction()
  // ReadDataset's TIN: the adaptive TIN of the grid `grid` (every used cell with data a vertex,
  // no face yet) with its vertices in row order, the grid's holes cut out of it exactly (`file_crs`
  // places them); fills `info`'s deviations.
  static absl::StatusOr<MeshData> BuildTin(const Dem& grid, const DemOptions& options, bool flip,
                                           const OGRSpatialReference& file_crs,
                                           const std::string& name, DemInfo* info);
  // Used cell (col, row)'s centre in the mesh's x y (metres; projected when reprojected).
  absl::StatusOr<std::array<double, 2>> CellCentreInMesh(uint32_t col, uint32_t row) const;
  // FromMesh's TIN part: the maps above from the mesh (cell_uv_ set).
  absl::Status MapTin();
  // DropMeshPoint on a TIN: a walk from the face of the nearest cell.
  absl::StatusOr<SurfacePoint> DropOnTin(double mx, double my, double u, double v,
                                         const std::string& name) const;
};

// A field's values at the used grid's cells, row by row (what the rasters hold): on the grid each
// cell's vertex's; on a TIN at the point below the cell's centre (CellPoint), with the nearest
// source's label: exact (one targeted solve from the field's sources that stops once every cell
// is final, as ComputePointValues) when `exact` options are given, else the paper's section-4
// estimate from the field (exact at the TIN's vertices and for a source in the point's own face;
// it can err by a percent behind an obstacle that large faces straddle). Cells in a hole: +inf and
// kNoVertex, with `hole` set.
struct CellValues {
  std::vector<double> distance;
  std::vector<uint32_t> source;
  std::vector<uint8_t> hole;
  bool estimated = false;    // some value is the section-4 estimate (a TIN without `exact`)
  bool travel_time = false;  // the values are seconds (a travel-cost field), not metres
  SolveStats exact_stats;    // the targeted solve's, when there was one
  Provenance provenance;     // what made the values, recorded in the rasters (the caller's)
};
// `mesh`: the engine's mesh of dem.mesh() when the caller has one (a TIN's values need it; null:
// built here, a TIN being small). The CLI and geodexd pass `exact` (the field's own options): a
// raster is then the exact field at every cell centre, at the cost of about a second solve on
// the TIN (docs/performance.md).
absl::StatusOr<CellValues> SampleCells(const Dem& dem, const DistanceField& field,
                                       const TriangleMesh* mesh = nullptr,
                                       const GeodesicOptions* exact = nullptr);

// True when `path` names a raster by its extension (.tif, .tiff, .vrt, .asc, .img, .hgt, .dem,
// .bil, .nc): what the CLI reads as a DEM instead of a mesh file.
bool IsDemPath(const std::string& path);
// True for .tif and .tiff: what an upload sends as GeoTIFF bytes instead of a mesh.
bool IsGeoTiffPath(const std::string& path);
// True when `bytes` start like a TIFF file (either byte order; BigTIFF too).
bool LooksLikeTiff(const std::string& bytes);

}  // namespace geodex::terrain
