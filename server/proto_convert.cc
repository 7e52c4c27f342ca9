#include "proto_convert.h"

#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "geodex/mesh_id.h"
#include "google/protobuf/util/time_util.h"
#include "status_convert.h"
#include "terrain_convert.h"

namespace geodex::server {
namespace {

// Whether file vertices a and b share an edge (over every internal copy of a).
bool HasFileEdge(const TriangleMesh& mesh, uint32_t a, uint32_t b) {
  auto touches = [&](uint32_t v) {
    for (uint32_t i = mesh.NeighborBegin(v); i < mesh.NeighborEnd(v); ++i) {
      if (mesh.FileVertex(mesh.NeighborVertex(i)) == b) return true;
    }
    return false;
  };
  if (touches(a)) return true;
  const std::vector<uint32_t>& copies = mesh.copy_of();
  for (size_t i = 0; i < copies.size(); ++i) {
    if (copies[i] == a && touches(mesh.file_vertex_count() + static_cast<uint32_t>(i))) return true;
  }
  return false;
}

}  // namespace

absl::StatusOr<std::string> ParseMeshName(const std::string& name, const std::string& field) {
  constexpr absl::string_view kPrefix = "meshes/";
  if (!absl::StartsWith(name, kPrefix) || name.size() == kPrefix.size() ||
      name.find('/', kPrefix.size()) != std::string::npos) {
    return FieldError(
        field, absl::StrCat("expected \"meshes/{mesh_id}\" or \"meshes/{display_name}\", got ",
                            QuoteInput(name)));
  }
  return name.substr(kPrefix.size());
}

absl::Status ValidateDisplayName(const std::string& name, const std::string& field) {
  if (name.empty()) return absl::OkStatus();
  bool ok = name.size() <= 63 && !IsMeshId(name);
  for (char c : name) {
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '.' || c == '_' || c == '-');
  }
  if (!ok) {
    return FieldError(
        field,
        absl::StrCat(QuoteInput(name),
                     " must be 1-63 characters of [A-Za-z0-9._-] and not a 64-digit hex id"));
  }
  return absl::OkStatus();
}

void MeshToProto(const StoredMesh& mesh, v1::Mesh* out) {
  api::MeshSummaryToProto(mesh.summary, out);
  out->set_name(absl::StrCat("meshes/", mesh.id));
  out->set_display_name(mesh.display_name);
  for (const std::string& alias : mesh.aliases) out->add_aliases(alias);
  out->set_vertex_count(mesh.vertex_count);
  out->set_face_count(mesh.face_count);
  out->set_upload_bytes(mesh.upload_bytes);
  out->set_memory_bytes(mesh.memory_bytes);
  *out->mutable_create_time() =
      google::protobuf::util::TimeUtil::NanosecondsToTimestamp(absl::ToUnixNanos(mesh.create_time));
  out->set_pinned(mesh.pinned);
  if (mesh.terrain) api::TerrainToProto(*mesh.terrain, out->mutable_terrain());
}

absl::StatusOr<PointSnaps> SnapsFromRequest(bool has_max_snap, double max_snap) {
  PointSnaps out;
  if (has_max_snap) {
    if (!(max_snap > 0)) {  // also NaN
      return FieldError("max_snap", absl::StrCat("must be > 0 when set, got ", max_snap));
    }
    out.max_snap = max_snap;
  }
  return out;
}

namespace {

// One point; `*snap` is how far a position moved (left 0 otherwise).
absl::StatusOr<SurfacePoint> ResolveOne(const StoredMesh& mesh, const v1::SurfacePoint& point,
                                        const std::string& field, double max_snap, double* snap) {
  SurfacePoint p;
  switch (point.point_case()) {
    case v1::SurfacePoint::kVertex:
      if (point.vertex() >= mesh.vertex_count) {
        return FieldError(absl::StrCat(field, ".vertex"),
                          VertexOutOfRange(SurfacePoint::AtVertex(point.vertex()), point.vertex(),
                                           static_cast<uint32_t>(mesh.vertex_count))
                              .message());
      }
      return SurfacePoint::AtVertex(point.vertex());
    case v1::SurfacePoint::kEdge: {
      const v1::EdgePoint& e = point.edge();
      if (!std::isfinite(e.t())) {
        return FieldError(absl::StrCat(field, ".edge.t"), "must be finite");
      }
      p = SurfacePoint::OnEdge(e.from(), e.to(), e.t());
      break;
    }
    case v1::SurfacePoint::kFace: {
      const v1::FacePoint& f = point.face();
      if (!std::isfinite(f.b0()) || !std::isfinite(f.b1()) || !std::isfinite(f.b2())) {
        return FieldError(absl::StrCat(field, ".face"), "barycentrics must be finite");
      }
      p = SurfacePoint::InFace(f.face(), f.b0(), f.b1(), f.b2());
      break;
    }
    case v1::SurfacePoint::kPosition: {
      const v1::Position& q = point.position();
      absl::StatusOr<LocatedPoint> located = mesh.locator->Locate({q.x(), q.y(), q.z()});
      absl::Status status = located.status();
      if (status.ok()) status = CheckSnapDistance({q.x(), q.y(), q.z()}, *located, max_snap);
      if (!status.ok()) return FieldError(absl::StrCat(field, ".position"), status.message());
      *snap = located->distance;
      return located->point;
    }
    case v1::SurfacePoint::kMapPoint:
    case v1::SurfacePoint::kLonLat: {
      const bool map = point.point_case() == v1::SurfacePoint::kMapPoint;
      const std::string where = absl::StrCat(field, map ? ".map_point" : ".lon_lat");
      if (mesh.dem == nullptr) {
        return FieldError(where,
                          "the mesh is not a DEM's (upload a GeoTIFF): map points need its map");
      }
      absl::StatusOr<SurfacePoint> dropped =
          map ? mesh.dem->DropMapPoint(point.map_point().x(), point.map_point().y())
              : mesh.dem->DropLonLat(point.lon_lat().lon(), point.lon_lat().lat());
      if (!dropped.ok()) return FieldError(where, dropped.status().message());
      return *dropped;
    }
    case v1::SurfacePoint::POINT_NOT_SET:
      return FieldError(field, "no point set (vertex, edge, face, position, map_point or lon_lat)");
  }
  absl::Status valid = ValidateSurfacePoint(*mesh.mesh, p);
  if (!valid.ok()) {
    return FieldError(absl::StrCat(field, p.kind == SurfacePoint::Kind::kEdge ? ".edge" : ".face"),
                      valid.message());
  }
  if (p.kind == SurfacePoint::Kind::kEdge && !HasFileEdge(*mesh.mesh, p.edge_from, p.edge_to)) {
    return FieldError(absl::StrCat(field, ".edge"),
                      absl::StrCat("the mesh has no edge between ", "vertices ", p.edge_from,
                                   " and ", p.edge_to));
  }
  return p;
}

}  // namespace

absl::StatusOr<SurfacePoint> ResolvePoint(const StoredMesh& mesh, const v1::SurfacePoint& point,
                                          const std::string& field, PointSnaps* snaps) {
  double snap = 0;
  absl::StatusOr<SurfacePoint> out = ResolveOne(mesh, point, field, snaps->max_snap, &snap);
  if (out.ok()) snaps->distances.push_back(snap);
  return out;
}

std::string OptionFieldName(const std::string& option, const std::string& field) {
  // The weighted engine's names (weighted_field.h): it runs only under a travel cost.
  constexpr absl::string_view kWeight = "face_weight";
  if (absl::StartsWith(option, kWeight)) {
    return absl::StrCat(field, ".travel.face_weights", option.substr(kWeight.size()));
  }
  if (option == "epsilon") return absl::StrCat(field, ".travel.epsilon");
  // The slope cost is made from the speed model's table (core's travel_cost.cc).
  if (option == "slope_cost") return absl::StrCat(field, ".travel.speed_table");
  return absl::StrCat(field, ".", option);
}

absl::StatusOr<GeodesicOptions> SolverOptionsFromProto(const v1::SolverOptions& options,
                                                       uint64_t max_windows,
                                                       uint64_t max_steiner_points,
                                                       const std::string& field) {
  absl::StatusOr<GeodesicOptions> out = api::SolverOptionsFromProto(options);
  if (!out.ok())
    return FieldError(OptionFieldName(InvalidOptionOf(out.status()), field),
                      out.status().message());
  out->max_windows = max_windows;
  if (out->travel) out->travel->max_steiner_points = max_steiner_points;
  return out;
}

}  // namespace geodex::server
