// Private to libgeodex_terrain: what the DEM reader's files share (dem.cc, crs.cc, vector_input.cc,
// dem_barriers.cc, friction.cc, point_files.cc, dem_tin.cc, map_points.cc, rasters.cc; they were
// one file). Each is described where it is defined.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "cpl_json.h"
#include "cpl_string.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/mesh_data.h"
#include "geodex/terrain.h"
#include "mem_file.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"

namespace geodex::terrain::dem_internal {

// crs.cc

std::string Shortest(double value);
std::string WktOf(const OGRSpatialReference& srs);
using TransformPtr =
    std::unique_ptr<OGRCoordinateTransformation, decltype(&OGRCoordinateTransformation::DestroyCT)>;
TransformPtr MakeTransform(const OGRSpatialReference& from, const OGRSpatialReference& to);
std::string InconsistentCrsId(const OGRSpatialReference& srs);
TransformPtr FileMeshTransform(const DemInfo& info, bool to_mesh);
double DegreesPerUnit(const std::string& wkt);
void LongitudesToGrid(const DemInfo& info, double* xs, size_t n);
absl::Status ParseFileCrs(const DemInfo* dem, const std::string& name, OGRSpatialReference* crs);

// vector_input.cc

absl::StatusOr<TransformPtr> LayerToCrs(OGRLayer& layer, const OGRSpatialReference* crs,
                                        const std::string& name);
absl::Status CheckGeoJsonCrs(const CPLJSONObject& node, const std::string& where);
CPLStringList SideCarsOf(const std::string& path);
absl::StatusOr<GDALDatasetUniquePtr> OpenBarrierFile(const std::string& path,
                                                     const std::string& name);

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

// dem.cc

GDALDatasetUniquePtr OpenUserRaster(const std::string& path);

// dem_barriers.cc

absl::StatusOr<std::unique_ptr<OGRGeometry>> BarrierPolygonsOf(GDALDataset* ds,
                                                               const std::string& name,
                                                               const OGRSpatialReference* crs);
std::unique_ptr<OGRGeometry> JoinCollections(std::unique_ptr<OGRGeometry> a,
                                             std::unique_ptr<OGRGeometry> b);
std::string FlagFilesName(absl::string_view flag, const std::vector<std::string>& paths);
absl::Status PolygonsToMeshFrame(OGRGeometry& polygons, const DemInfo* dem,
                                 const OGRSpatialReference* file_crs, const std::string& name,
                                 double* scale);
absl::StatusOr<MeshData> CutBarrier(const MeshData& mesh, OGRGeometry& polygons, const DemInfo* dem,
                                    const OGRSpatialReference* file_crs, double width,
                                    uint64_t max_vertices, const std::string& name,
                                    CutStats* stats);

// friction.cc

// One friction polygon (or multipolygon) with its value.
struct FrictionRegion {
  std::unique_ptr<OGRGeometry> shape;
  double friction;
};

absl::StatusOr<std::vector<FrictionRegion>> ReadFrictionRegions(GDALDataset& ds,
                                                                const OGRSpatialReference* crs,
                                                                const std::string& name);
// Each face's friction under its centre: `regions` in the map (the DEM's CRS) with `dem`, in the
// mesh's own x y without.
absl::StatusOr<std::vector<double>> FaceFrictionOf(std::vector<FrictionRegion> regions,
                                                   const MeshData& mesh, const DemInfo* dem,
                                                   const std::string& name);
std::unique_ptr<OGRGeometry> OutlinesOf(const std::vector<FrictionRegion>& regions);
absl::StatusOr<MeshData> CutOutlines(const MeshData& mesh, OGRGeometry& polygons,
                                     const DemInfo* dem, const OGRSpatialReference* file_crs,
                                     uint64_t max_vertices, const std::string& name,
                                     CutStats* stats);
absl::Status RegionsToMeshFrame(std::vector<FrictionRegion>& regions, const DemInfo& dem,
                                const OGRSpatialReference& file_crs, const std::string& name);
void SnapOutlinesToVertices(std::vector<FrictionRegion>& regions, const MeshData& mesh,
                            double fraction);

}  // namespace geodex::terrain::dem_internal
