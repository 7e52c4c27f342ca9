// Barriers on a DEM's mesh (or any mesh): the polygons, lines and points of barrier files and
// GeoJSON texts read and joined, brought to the mesh's frame and cut out of it (the geometric cut
// itself is barrier_cut.cc), their names in messages, and the faces below a level removed.

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "barrier_cut.h"
#include "dem_internal.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/terrain.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"

namespace geodex::terrain {

namespace dem_internal {

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

}  // namespace dem_internal

using dem_internal::BarrierPolygonsOf;
using dem_internal::CutBarrier;
using dem_internal::FlagFilesName;
using dem_internal::JoinCollections;
using dem_internal::ParseFileCrs;
using dem_internal::WithGeoJsonText;

std::string BarrierFilesName(const std::vector<std::string>& paths) {
  return FlagFilesName("barrier", paths);
}

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

}  // namespace geodex::terrain
