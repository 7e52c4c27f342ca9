// GIS files of a DEM's mesh streamed: ExportGis. The products are built by terrain/ (geojson.h,
// Dem's rasters), the same code the CLI writes its --output FILE.geojson / FILE.tif with, so a
// file from geodexd is the file the CLI makes locally.

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "geodex/delaunay.h"
#include "geodex/distance_matrix.h"
#include "geodex/geojson.h"
#include "geodex/isolines.h"
#include "geodex/shortest_path.h"
#include "geodex/terrain.h"
#include "geodex/voronoi.h"
#include "geometry_convert.h"
#include "proto_convert.h"
#include "queries.h"
#include "query_support.h"
#include "service_limits.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

// A request point as a user of the CLI writes it (the GeoJSON `point` property).
std::string SpecOf(const v1::SurfacePoint& p) {
  switch (p.point_case()) {
    case v1::SurfacePoint::kVertex:
      return absl::StrCat(p.vertex());
    case v1::SurfacePoint::kEdge:
      return absl::StrFormat("e:%d:%d:%.17g", p.edge().from(), p.edge().to(), p.edge().t());
    case v1::SurfacePoint::kFace:
      return absl::StrFormat("f:%d:%.17g:%.17g:%.17g", p.face().face(), p.face().b0(),
                             p.face().b1(), p.face().b2());
    case v1::SurfacePoint::kPosition:
      return absl::StrFormat("p:%.17g:%.17g:%.17g", p.position().x(), p.position().y(),
                             p.position().z());
    case v1::SurfacePoint::kMapPoint:
      return absl::StrFormat("g:%.17g:%.17g", p.map_point().x(), p.map_point().y());
    case v1::SurfacePoint::kLonLat:
      return absl::StrFormat("ll:%.17g:%.17g", p.lon_lat().lon(), p.lon_lat().lat());
    case v1::SurfacePoint::POINT_NOT_SET:
      break;
  }
  return "";
}

// The file, cut into messages of at most --stream_chunk_bytes (the request points' snap
// distances and the travel cost's bound in the first); a file over 8 bytes per
// --max_output_values is refused.
absl::StatusOr<MessageStream<v1::ExportGisResponse>> FileStream(
    const std::string& bytes, const char* media_type, uint32_t chunk_bytes,
    uint64_t max_output_values, const PointSnaps& snaps, double travel_epsilon, bool travel_exact) {
  if (bytes.size() / 8 > max_output_values) {
    return ServerLimitError(
        "max_output_values",
        absl::StrCat("the file would be ", bytes.size(),
                     " bytes, over 8 per value of --max_output_values=", max_output_values));
  }
  std::vector<v1::ExportGisResponse> messages;
  for (size_t offset = 0; offset < bytes.size() || messages.empty(); offset += chunk_bytes) {
    v1::ExportGisResponse& m = messages.emplace_back();
    if (offset == 0) {
      m.set_media_type(media_type);
      SnapsToProto(snaps, &m);
      m.set_travel_epsilon(travel_epsilon);
      m.set_travel_exact(travel_exact);
    }
    m.set_data(bytes.substr(offset, chunk_bytes));
  }
  return ProducerOf(std::move(messages));
}

}  // namespace

absl::StatusOr<MessageStream<v1::ExportGisResponse>> RunExportGis(
    const QueryEnv& env, const v1::ExportGisRequest& request) {
  const v1::GisProduct product = request.product();
  if (product == v1::GIS_PRODUCT_UNSPECIFIED || !v1::GisProduct_IsValid(product)) {
    return FieldError("product", absl::StrCat("unknown value ", static_cast<int>(product)));
  }
  absl::StatusOr<std::shared_ptr<const StoredMesh>> found = LookupMesh(env, request.mesh(), "mesh");
  if (!found.ok()) return found.status();
  if ((*found)->dem == nullptr) {
    return FieldError("mesh", "not a DEM's mesh (upload a GeoTIFF): GIS files need its map");
  }
  const terrain::Dem& dem = *(*found)->dem;
  absl::StatusOr<PointSnaps> snaps = SnapsOf(request);
  if (!snaps.ok()) return snaps.status();
  if (product == v1::GIS_PRODUCT_DELAUNAY) {
    if (absl::Status s = RefuseTravel(request.options(), kDelaunayNeedsOrigins); !s.ok()) return s;
  }
  const uint32_t chunk = env.limits->stream_chunk_bytes;
  const char* kGeoJson = "application/geo+json";
  double travel_epsilon = 0;  // set once the options are resolved
  bool travel_exact = false;
  // What made the file, recorded in it (terrain::Provenance): the request, and its options once
  // they are resolved.
  const std::string made_by =
      absl::StrCat("geodexd ExportGis ", v1::GisProduct_Name(product), " ", request.mesh());
  terrain::Provenance provenance = terrain::MakeProvenance(made_by, nullptr);
  auto geojson_of = [&](const terrain::Dem& on, const std::vector<terrain::GeoFeature>& features)
      -> absl::StatusOr<MessageStream<v1::ExportGisResponse>> {
    if (env.cancel->IsCancelled()) return absl::CancelledError("export cancelled");
    absl::StatusOr<std::string> text =
        terrain::GeoJsonText(on.info(), features, request.native_crs(), &provenance);
    if (!text.ok()) return text.status();
    return FileStream(*text, kGeoJson, chunk, env.limits->max_output_values, *snaps, travel_epsilon,
                      travel_exact);
  };
  auto geojson = [&](const std::vector<terrain::GeoFeature>& features) {
    return geojson_of(dem, features);
  };

  if (product == v1::GIS_PRODUCT_PATH || product == v1::GIS_PRODUCT_POINTS) {
    const StoredMesh& mesh = **found;
    absl::StatusOr<GeodesicOptions> solver = Options(env, mesh, request.options());
    if (!solver.ok()) return solver.status();
    travel_epsilon = TravelEpsilon(*solver);
    travel_exact = TravelExact(*solver);
    provenance = terrain::MakeProvenance(made_by, &*solver);
    if (product == v1::GIS_PRODUCT_PATH) {
      if (request.sources_size() != 1 || request.points_size() != 1) {
        return FieldError(request.sources_size() != 1 ? "sources" : "points",
                          "a path needs exactly one source (its start) and one point (its end)");
      }
      absl::StatusOr<SurfacePoint> from =
          ResolvePoint(mesh, request.sources(0), "sources[0]", &*snaps);
      if (!from.ok()) return from.status();
      absl::StatusOr<SurfacePoint> to = ResolvePoint(mesh, request.points(0), "points[0]", &*snaps);
      if (!to.ok()) return to.status();
      PathQueryOptions options;
      options.solver = *solver;
      absl::StatusOr<PathQueryResult> path = ComputeShortestPath(*mesh.mesh, *from, *to, options);
      if (absl::IsNotFound(path.status()))
        return UnreachableError("points[0]: unreachable from sources[0]");
      if (!path.ok()) return NameSolveError(path.status(), "sources");
      return geojson(
          {terrain::PathFeature(path->path.points, path->path.length,
                                solver->travel.has_value() ? path->distance : std::nan(""))});
    }
    absl::StatusOr<std::vector<SurfacePoint>> sources =
        ResolveSources(env, mesh, request.sources(), &*snaps);
    if (!sources.ok()) return sources.status();
    absl::StatusOr<std::vector<SurfacePoint>> points = ResolvePoints(
        mesh, request.points(), "points", env.limits->max_targets, "max_targets", &*snaps);
    if (!points.ok()) return points.status();
    absl::StatusOr<std::vector<std::pair<double, uint32_t>>> exact =
        ComputeExactDistancesAt(*mesh.mesh, *sources, *points, *solver);
    if (!exact.ok()) return NameSolveError(exact.status(), "sources");
    std::vector<terrain::PointValue> values;
    for (size_t i = 0; i < points->size(); ++i) {
      const auto& [distance, label] = (*exact)[i];
      values.push_back({PositionOf(dem.mesh(), (*points)[i]),
                        SpecOf(request.points(static_cast<int>(i))),
                        SurfacePointToString((*points)[i]), distance,
                        std::isfinite(distance) ? int64_t{label} : -1});
    }
    return geojson(
        terrain::PointFeatures(values, solver->travel.has_value() ? &*solver->travel : nullptr));
  }

  // The rest is made from the field of `sources` (cached like any field).
  absl::StatusOr<IsolineOptions> levels;
  if (product == v1::GIS_PRODUCT_ISOCHRONES) {
    levels = IsolineLevels(env, api::IsolineLevelsFromProto(request.levels(), request.count()));
    if (!levels.ok()) return levels.status();
  }
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options(), *snaps,
                 levels.ok() ? &*levels : nullptr);
  if (!solved.ok()) return solved.status();
  *snaps = solved->snaps;  // the sources' distances, for the file's first message
  travel_epsilon = solved->field->travel_epsilon;
  travel_exact = solved->field->travel_exact;
  provenance = terrain::MakeProvenance(made_by, &solved->options);
  const TriangleMesh& mesh = *solved->mesh->mesh;
  const DistanceField& field = *solved->field;
  // The mesh the field was solved on (the name was looked up again: it may name another mesh now).
  if (solved->mesh->dem == nullptr) {
    return FieldError("mesh", "not a DEM's mesh (upload a GeoTIFF): GIS files need its map");
  }
  const terrain::Dem& grid = *solved->mesh->dem;
  switch (product) {
    case v1::GIS_PRODUCT_ISOCHRONES: {
      absl::StatusOr<Isolines> iso = ExtractIsolines(mesh, field, *levels);  // its levels
      if (!iso.ok()) return iso.status();
      const GeodesicOptions& options = solved->options;
      return geojson_of(grid, terrain::IsochroneFeatures(
                                  grid.mesh(), field.distance, iso->levels,
                                  options.travel.has_value() ? &*options.travel : nullptr));
    }
    case v1::GIS_PRODUCT_VORONOI: {
      absl::StatusOr<VoronoiDiagram> diagram = BuildVoronoi(
          mesh, field, solved->options.travel.has_value() ? &*solved->options.travel : nullptr);
      if (!diagram.ok()) return diagram.status();
      return geojson_of(grid, terrain::VoronoiFeatures(grid.mesh(), *diagram));
    }
    case v1::GIS_PRODUCT_DELAUNAY: {
      absl::StatusOr<DelaunayTriangulation> delaunay = BuildDelaunay(mesh, field);
      if (!delaunay.ok()) return delaunay.status();
      return geojson_of(grid, terrain::DelaunayFeatures(*delaunay));
    }
    case v1::GIS_PRODUCT_DISTANCE_RASTER:
    case v1::GIS_PRODUCT_LABEL_RASTER: {
      // The used grid's cells (on a TIN: solved exactly at the point below each centre).
      absl::StatusOr<terrain::CellValues> cells =
          terrain::SampleCells(grid, field, &mesh, &solved->options);
      if (!cells.ok()) return NameSolveError(cells.status(), "sources");
      cells->provenance = provenance;
      absl::StatusOr<std::string> tiff = product == v1::GIS_PRODUCT_DISTANCE_RASTER
                                             ? grid.DistanceRasterBytes(*cells)
                                             : grid.LabelRasterBytes(*cells);
      if (!tiff.ok()) return tiff.status();
      return FileStream(*tiff, "image/tiff", chunk, env.limits->max_output_values, *snaps,
                        travel_epsilon, travel_exact);
    }
    default:
      break;
  }
  return absl::InternalError("unhandled GIS product");
}

}  // namespace geodex::server
