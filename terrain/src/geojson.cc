#include "geodex/geojson.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "cpl_error.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/gis_formats.h"
#include "mem_file.h"
#include "ogr_geometry.h"
#include "ogrsf_frmts.h"

namespace geodex::terrain {
namespace {

// Mesh x y back to the CRS the geometry is built in: the mesh's when reprojected (UTM), else the
// file's (whose unit may be feet: the mesh is in metres).
std::array<double, 2> ToCrs(const DemInfo& dem, double x, double y) {
  return {x / dem.horizontal_scale, y / dem.horizontal_scale};
}

std::unique_ptr<OGRGeometry> AreaOf(const DemInfo& dem, const std::vector<Polygon2>& pieces) {
  auto all = std::make_unique<OGRMultiPolygon>();
  for (const Polygon2& piece : pieces) {
    if (piece.size() < 3) continue;
    auto ring = std::make_unique<OGRLinearRing>();
    for (const auto& p : piece) {
      const auto q = ToCrs(dem, p[0], p[1]);
      ring->addPoint(q[0], q[1]);
    }
    ring->closeRings();
    if (std::abs(ring->get_Area()) <= 0) continue;  // a sliver of nothing
    auto polygon = std::make_unique<OGRPolygon>();
    polygon->addRingDirectly(ring.release());
    all->addGeometryDirectly(polygon.release());
  }
  if (all->IsEmpty()) return all;
  std::unique_ptr<OGRGeometry> merged(all->UnionCascaded());
  if (merged == nullptr) return nullptr;
  return merged;
}

// The union of pieces that tile it exactly: every piece edge shared with a neighbour (the same two
// points, the other way round) is inside; the rest are the boundary, with the area on their left.
// Chained into rings (at a vertex where several boundary edges leave, the sharpest left turn, so
// that lobes touching at a point stay separate rings), they are organised into polygons by their
// orientation: counter-clockwise shells, clockwise holes (reversed for organizePolygons).
std::unique_ptr<OGRGeometry> TiledAreaOf(const DemInfo& dem, const std::vector<Polygon2>& pieces) {
  using Point = std::array<double, 2>;
  std::map<std::pair<Point, Point>, int> edges;  // directed edge -> count (ordered: deterministic)
  for (const Polygon2& piece : pieces) {
    double twice_area = 0;
    for (size_t k = 0; k < piece.size(); ++k) {
      const Point& a = piece[k];
      const Point& b = piece[(k + 1) % piece.size()];
      twice_area += a[0] * b[1] - b[0] * a[1];
    }
    if (!(twice_area > 0)) continue;  // degenerate (or not counter-clockwise: not a tile)
    for (size_t k = 0; k < piece.size(); ++k) {
      const Point& a = piece[k];
      const Point& b = piece[(k + 1) % piece.size()];
      if (a == b) continue;
      auto reverse = edges.find({b, a});
      if (reverse != edges.end()) {  // shared with a neighbour: inside the union
        if (--reverse->second == 0) edges.erase(reverse);
      } else {
        ++edges[{a, b}];
      }
    }
  }
  std::multimap<Point, Point> from;  // boundary edges by their start
  for (const auto& [edge, count] : edges) {
    for (int c = 0; c < count; ++c) from.emplace(edge.first, edge.second);
  }
  std::vector<OGRGeometry*> rings;  // each as a polygon, for organizePolygons
  while (!from.empty()) {
    auto ring = std::make_unique<OGRLinearRing>();
    const Point start = from.begin()->first;
    Point at = start, next = from.begin()->second;
    from.erase(from.begin());
    auto add = [&](const Point& p) {
      const auto q = ToCrs(dem, p[0], p[1]);
      ring->addPoint(q[0], q[1]);
    };
    add(at);
    while (next != start) {
      add(next);
      auto [lo, hi] = from.equal_range(next);
      if (lo == hi) break;  // an open chain cannot happen for a tiling; close it anyway
      // The sharpest left turn from the incoming direction.
      const double in = std::atan2(next[1] - at[1], next[0] - at[0]);
      auto best = lo;
      double best_turn = -10;
      for (auto it = lo; it != hi; ++it) {
        double turn = std::atan2(it->second[1] - next[1], it->second[0] - next[0]) - in;
        while (turn <= -M_PI) turn += 2 * M_PI;
        while (turn > M_PI) turn -= 2 * M_PI;
        if (turn > best_turn) {
          best_turn = turn;
          best = it;
        }
      }
      at = next;
      next = best->second;
      from.erase(best);
    }
    ring->closeRings();
    if (ring->getNumPoints() < 4) continue;
    // organizePolygons' ONLY_CCW takes counter-clockwise rings for holes (the shapefile's
    // convention): turn ours round. The writer orients rings as the output format wants.
    ring->reverseWindingOrder();
    auto polygon = std::make_unique<OGRPolygon>();
    polygon->addRingDirectly(ring.release());
    rings.push_back(polygon.release());
  }
  if (rings.empty()) return std::make_unique<OGRMultiPolygon>();
  int valid = 0;
  const char* options[] = {"METHOD=ONLY_CCW", nullptr};
  return std::unique_ptr<OGRGeometry>(OGRGeometryFactory::organizePolygons(
      rings.data(), static_cast<int>(rings.size()), &valid, options));
}

}  // namespace

std::vector<Polygon2> SublevelPieces(const MeshData& mesh, const std::vector<double>& value,
                                     double level) {
  std::vector<Polygon2> out;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    Polygon2 piece;
    for (int c = 0; c < 3; ++c) {
      const size_t u = mesh.faces[3 * f + c], v = mesh.faces[3 * f + (c + 1) % 3];
      const double* pu = &mesh.positions[3 * u];
      if (value[u] <= level) piece.push_back({pu[0], pu[1]});
      if ((value[u] <= level) != (value[v] <= level)) {  // the level crosses edge u-v
        // From the lower vertex id, so that both faces of an edge make the very same point and
        // their pieces meet without a sliver.
        const size_t a = std::min(u, v), b = std::max(u, v);
        const double da = value[a], db = value[b];
        const double* pa = &mesh.positions[3 * a];
        const double* pb = &mesh.positions[3 * b];
        double t =
            std::isinf(da) || std::isinf(db) ? (da <= level ? 0.0 : 1.0) : (level - da) / (db - da);
        t = std::clamp(t, 0.0, 1.0);
        piece.push_back({pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1])});
      }
    }
    if (piece.size() >= 3) out.push_back(std::move(piece));
  }
  return out;
}

absl::Status WriteVectorFile(const DemInfo& dem, const std::vector<GeoFeature>& features,
                             const std::string& path, bool native_crs,
                             const Provenance* provenance) {
  QuietGdal quiet;
  auto failed = [&](const std::string& why) {
    return absl::PermissionDeniedError(absl::StrCat("cannot write ", path, ": ", why));
  };
  const GisFormat* format = GisFormatOf(path);
  if (format == nullptr || format->kind != GisFileKind::kVector) {
    return absl::InvalidArgumentError(absl::StrCat(
        "cannot write ", path, ": a vector file is one of ", GisExtensions(GisFileKind::kVector)));
  }
  if (!OGRGeometryFactory::haveGEOS()) return absl::InternalError("GDAL was built without GEOS");
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(format->driver);
  if (driver == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot write ", path, ": this GDAL writes no ", format->description));
  }
  const bool geojson = std::string(format->driver) == "GeoJSON";
  native_crs =
      native_crs || !geojson;  // RFC 7946 is GeoJSON's; every other format keeps the DEM's CRS
  RemoveOldOutput(path);       // the driver will not overwrite
  GDALDatasetUniquePtr ds(driver->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (ds == nullptr) return failed(QuietGdal::LastMessage());
  // Geometries are built in the mesh's CRS when it was reprojected, else in the file's.
  OGRSpatialReference built, file;
  built.importFromWkt((dem.reprojected ? dem.mesh_crs_wkt : dem.file_crs_wkt).c_str());
  built.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  file.importFromWkt(dem.file_crs_wkt.c_str());
  file.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  CPLStringList layer_options;
  if (geojson) {
    if (!native_crs) layer_options.AddString("RFC7946=YES");
    layer_options.AddString("WRITE_NAME=NO");
    if (provenance != nullptr) {  // a foreign member of the FeatureCollection: "geodex": {...}
      layer_options.SetNameValue(
          "NATIVE_DATA", absl::StrCat("{\"geodex\": ", ProvenanceJson(*provenance), "}").c_str());
      layer_options.SetNameValue("NATIVE_MEDIA_TYPE", "application/vnd.geo+json");
    }
  }
  OGRLayer* layer = ds->CreateLayer("geodex", native_crs ? &file : &built, wkbUnknown,
                                    geojson ? layer_options.List() : nullptr);
  if (layer == nullptr) return failed(QuietGdal::LastMessage());
  if (provenance != nullptr && !geojson) {
    for (const auto& [key, value] : provenance->items) {
      layer->SetMetadataItem(absl::StrCat("GEODEX_", absl::AsciiStrToUpper(key)).c_str(),
                             value.c_str());
    }
  }
  std::unique_ptr<OGRCoordinateTransformation, decltype(&OGRCoordinateTransformation::DestroyCT)>
      to_file(nullptr, &OGRCoordinateTransformation::DestroyCT);
  if (native_crs && dem.reprojected) {
    to_file.reset(OGRCreateCoordinateTransformation(&built, &file));
    if (to_file == nullptr) {
      return failed(
          absl::StrCat("cannot project to the DEM's CRS (", QuietGdal::LastMessage(), ")"));
    }
  }

  // The fields: every property name in order of first appearance, typed by its first value that
  // is not null (a real number when every value is null).
  std::vector<std::pair<std::string, OGRFieldType>> fields;
  std::map<std::string, size_t> field_of;
  for (const GeoFeature& f : features) {
    for (const auto& [name, value] : f.properties) {
      auto [at, added] = field_of.emplace(name, fields.size());
      if (added) fields.push_back({name, OFTReal});
      if (std::holds_alternative<std::monostate>(value) ||
          (!added && fields[at->second].second != OFTReal))
        continue;
      fields[at->second].second = std::holds_alternative<double>(value)    ? OFTReal
                                  : std::holds_alternative<int64_t>(value) ? OFTInteger64
                                  : std::holds_alternative<bool>(value)    ? OFTInteger
                                                                           : OFTString;
    }
  }
  for (const auto& [name, type] : fields) {
    OGRFieldDefn field(name.c_str(), type);
    if (type == OFTInteger) field.SetSubType(OFSTBoolean);  // (bool is the only OFTInteger)
    if (layer->CreateField(&field) != OGRERR_NONE) return failed(QuietGdal::LastMessage());
  }
  for (const GeoFeature& f : features) {
    std::unique_ptr<OGRGeometry> geometry;
    switch (f.kind) {
      case GeoFeature::Kind::kArea:
        geometry = f.exact_tiling ? TiledAreaOf(dem, f.pieces) : AreaOf(dem, f.pieces);
        if (geometry == nullptr) return absl::InternalError("the polygon union failed");
        break;
      case GeoFeature::Kind::kLine: {
        auto line = std::make_unique<OGRLineString>();
        for (const auto& p : f.points) {
          const auto q = ToCrs(dem, p[0], p[1]);
          line->addPoint(q[0], q[1], p[2]);
        }
        geometry = std::move(line);
        break;
      }
      case GeoFeature::Kind::kPoint: {
        const auto q = ToCrs(dem, f.points.at(0)[0], f.points.at(0)[1]);
        geometry = std::make_unique<OGRPoint>(q[0], q[1], f.points.at(0)[2]);
        break;
      }
    }
    if (to_file != nullptr && !geometry->IsEmpty() &&
        geometry->transform(to_file.get()) != OGRERR_NONE) {
      return failed(
          absl::StrCat("cannot project to the DEM's CRS (", QuietGdal::LastMessage(), ")"));
    }
    OGRFeatureUniquePtr feature(OGRFeature::CreateFeature(layer->GetLayerDefn()));
    for (const auto& [name, value] : f.properties) {
      if (std::holds_alternative<std::monostate>(value)) {
        feature->SetFieldNull(feature->GetFieldIndex(name.c_str()));
      } else if (const double* d = std::get_if<double>(&value)) {
        feature->SetField(name.c_str(), *d);
      } else if (const int64_t* i = std::get_if<int64_t>(&value)) {
        feature->SetField(name.c_str(), static_cast<GIntBig>(*i));
      } else if (const bool* b = std::get_if<bool>(&value)) {
        feature->SetField(name.c_str(), *b ? 1 : 0);
      } else {
        feature->SetField(name.c_str(), std::get<std::string>(value).c_str());
      }
    }
    if (!geometry->IsEmpty()) feature->SetGeometryDirectly(geometry.release());
    if (layer->CreateFeature(feature.get()) != OGRERR_NONE) return failed(QuietGdal::LastMessage());
  }
  ds.reset();
  if (CPLGetLastErrorType() >= CE_Failure) return failed(QuietGdal::LastMessage());
  return absl::OkStatus();
}

absl::StatusOr<std::string> GeoJsonText(const DemInfo& dem, const std::vector<GeoFeature>& features,
                                        bool native_crs, const Provenance* provenance) {
  MemFile file(".geojson");
  if (absl::Status written = WriteVectorFile(dem, features, file.path(), native_crs, provenance);
      !written.ok()) {
    return absl::InternalError(written.message());
  }
  return file.Take();
}

std::vector<GeoFeature> IsochroneFeatures(const MeshData& mesh, const std::vector<double>& distance,
                                          const std::vector<double>& levels,
                                          const TravelCost* travel) {
  std::vector<GeoFeature> features;
  for (double level : levels) {
    GeoFeature f;
    f.kind = GeoFeature::Kind::kArea;
    f.pieces = SublevelPieces(mesh, distance, level);
    f.exact_tiling = true;
    f.properties = {{"level", level}, {"units", std::string(travel != nullptr ? "s" : "m")}};
    if (travel != nullptr) {
      f.properties.push_back({"epsilon", StatedTravelEpsilon(*travel)});
      f.properties.push_back({"bound", !IsDirectional(*travel)});
      f.properties.push_back({"speed", std::string(SpeedModelName(travel->speed_model))});
      f.properties.push_back({"inbound", TimesInbound(*travel)});
      f.properties.push_back({"exact", TravelIsExact(*travel)});
    }
    features.push_back(std::move(f));
  }
  return features;
}

std::vector<GeoFeature> VoronoiFeatures(const MeshData& mesh, const VoronoiDiagram& diagram) {
  std::vector<GeoFeature> features;
  for (const VoronoiCell& c : diagram.cells) {
    GeoFeature f;
    f.kind = GeoFeature::Kind::kArea;
    for (uint32_t face : c.whole_faces) {
      Polygon2 tri;
      for (int k = 0; k < 3; ++k) {
        const size_t v = mesh.faces[3 * size_t{face} + k];
        tri.push_back({mesh.positions[3 * v], mesh.positions[3 * v + 1]});
      }
      f.pieces.push_back(std::move(tri));
    }
    for (const VoronoiFragment& fr : c.fragments) {
      Polygon2 piece;
      for (const PathPoint& q : fr.polygon) piece.push_back({q.position[0], q.position[1]});
      f.pieces.push_back(std::move(piece));
    }
    f.properties = {{"site", int64_t{c.site}}, {"area", c.area}};
    features.push_back(std::move(f));
  }
  return features;
}

std::vector<GeoFeature> DelaunayFeatures(const DelaunayTriangulation& delaunay) {
  std::vector<GeoFeature> features;
  for (const DelaunayEdge& e : delaunay.edges) {
    GeoFeature f;
    f.kind = GeoFeature::Kind::kLine;
    for (const PathPoint& q : e.points) f.points.push_back(q.position);
    f.properties = {
        {"site_a", int64_t{e.site_a}}, {"site_b", int64_t{e.site_b}}, {"length", e.length}};
    features.push_back(std::move(f));
  }
  return features;
}

GeoFeature PathFeature(const std::vector<PathPoint>& points, double length_m, double time_s) {
  GeoFeature f;
  f.kind = GeoFeature::Kind::kLine;
  for (const PathPoint& q : points) f.points.push_back(q.position);
  f.properties = {{"length_m", length_m}, {"length", length_m}, {"units", std::string("m")}};
  if (!std::isnan(time_s)) f.properties.push_back({"time_s", time_s});
  return f;
}

std::vector<GeoFeature> PointFeatures(const std::vector<PointValue>& points,
                                      const TravelCost* travel) {
  std::vector<GeoFeature> features;
  const std::string value = travel != nullptr ? "time_s" : "distance";
  for (const PointValue& p : points) {
    GeoFeature f;
    f.points = {p.position};
    f.properties = {{"point", p.point}, {"surface_point", p.surface_point}};
    if (std::isfinite(p.distance)) {
      f.properties.push_back({value, p.distance});
      f.properties.push_back({"source", p.source});
    } else {  // unreachable: null, as the proto and docs say (not left out)
      f.properties.push_back({value, std::monostate()});
      f.properties.push_back({"source", std::monostate()});
    }
    f.properties.push_back({"units", std::string(travel != nullptr ? "s" : "m")});
    features.push_back(std::move(f));
  }
  return features;
}

}  // namespace geodex::terrain
