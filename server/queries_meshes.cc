// Mesh resources: GetMesh, ListMeshes, DeleteMesh (answered inline: map look-ups), GetMeshGeometry
// and DeriveMesh (on the pool: a derived mesh is built like an upload).

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "geodex/friction.h"
#include "geodex/limits.h"
#include "geodex/mesh_id.h"
#include "geodex/terrain.h"
#include "geometry_convert.h"
#include "proto_convert.h"
#include "queries.h"
#include "query_support.h"
#include "service_limits.h"
#include "status_convert.h"

namespace geodex::server {

// ------------------------------------------------------------------------------------------
// Mesh resources

absl::Status RunGetMesh(const QueryEnv& env, const v1::GetMeshRequest& request,
                        v1::Mesh* response) {
  absl::StatusOr<std::string> key = ParseMeshName(request.name(), "name");
  if (!key.ok()) return key.status();
  // The record: a mesh that is only on disk is described without loading it.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = env.store->GetRecord(*key);
  if (!mesh.ok()) {
    return MeshNotFoundError("name",
                             absl::StrCat("mesh ", QuoteInput(request.name()), " not found"));
  }
  MeshToProto(**mesh, response);
  return absl::OkStatus();
}

absl::Status RunListMeshes(const QueryEnv& env, const v1::ListMeshesRequest& request,
                           v1::ListMeshesResponse* response) {
  constexpr int kDefaultPageSize = 50;
  constexpr int kMaxPageSize = 1000;
  if (request.page_size() < 0) {
    return FieldError("page_size", absl::StrCat("must be >= 0, got ", request.page_size()));
  }
  if (!request.page_token().empty() && !IsMeshId(request.page_token())) {
    return FieldError("page_token", "not a token returned by ListMeshes");
  }
  const int page_size =
      request.page_size() == 0 ? kDefaultPageSize : std::min(request.page_size(), kMaxPageSize);
  bool more = false;
  std::vector<std::shared_ptr<const StoredMesh>> page =
      env.store->List(request.page_token(), static_cast<size_t>(page_size), &more);
  for (const auto& mesh : page) MeshToProto(*mesh, response->add_meshes());
  if (more && !page.empty()) response->set_next_page_token(page.back()->id);
  return absl::OkStatus();
}

absl::Status RunDeleteMesh(const QueryEnv& env, const v1::DeleteMeshRequest& request,
                           v1::DeleteMeshResponse* /*response*/) {
  absl::StatusOr<std::string> key = ParseMeshName(request.name(), "name");
  if (!key.ok()) return key.status();
  absl::Status status = env.store->Delete(*key);
  if (absl::IsNotFound(status)) {
    return MeshNotFoundError("name",
                             absl::StrCat("mesh ", QuoteInput(request.name()), " not found"));
  }
  return status;
}

absl::StatusOr<MessageStream<v1::MeshGeometry>> RunGetMeshGeometry(
    const QueryEnv& env, const v1::GetMeshGeometryRequest& request) {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = LookupMesh(env, request.name(), "name");
  if (!mesh.ok()) return mesh.status();
  return ProducerOf(
      api::MeshGeometryToProto((*mesh)->mesh->ToMeshData(), env.limits->stream_chunk_bytes));
}

absl::Status RunDeriveMesh(const QueryEnv& env, const v1::DeriveMeshRequest& request,
                           v1::Mesh* response) {
  const v1::Barrier& barrier = request.barrier();
  if (!barrier.has_below() && barrier.polygons_geojson().empty() &&
      request.friction_geojson().empty()) {
    return FieldError("barrier",
                      "empty: set below, polygons_geojson or both (or friction_geojson alone)");
  }
  if (barrier.has_below() && !std::isfinite(barrier.below())) {
    return FieldError("barrier.below", "must be finite");
  }
  if (!(barrier.width() >= 0) || !std::isfinite(barrier.width())) {
    return FieldError("barrier.width", "must be a finite number of metres, 0 or more");
  }
  if (absl::Status valid = ValidateDisplayName(request.display_name(), "display_name");
      !valid.ok()) {
    return valid;
  }
  absl::StatusOr<std::shared_ptr<const StoredMesh>> base = LookupMesh(env, request.mesh(), "mesh");
  if (!base.ok()) return base.status();
  const StoredMesh& from = **base;
  // A DEM's mesh keeps its exact file positions in its grid; any other comes from the built mesh.
  MeshData derived = from.dem != nullptr ? from.dem->mesh() : from.mesh->ToMeshData();
  const size_t faces_before = derived.face_count();
  if (barrier.has_below()) derived = terrain::RemoveFacesBelow(derived, barrier.below());
  uint64_t barrier_faces = faces_before - derived.face_count();
  if (!barrier.polygons_geojson().empty()) {
    terrain::CutStats cut_stats;
    absl::StatusOr<MeshData> cut = terrain::CutBarrierPolygons(
        derived, barrier.polygons_geojson(), from.terrain ? &*from.terrain : nullptr,
        barrier.width(), "barrier.polygons_geojson", &cut_stats, env.limits->max_vertices);
    if (ExceededLimit(cut.status())) return cut.status();  // names --max_vertices on the way out
    if (!cut.ok()) return FieldError("barrier.polygons_geojson", cut.status().message());
    derived = *std::move(cut);
    barrier_faces += cut_stats.faces_removed + cut_stats.faces_cut;
  }
  if (derived.faces.empty()) return FieldError("barrier", "covers every face of the mesh");
  if (!request.friction_geojson().empty()) {
    terrain::CutStats cut_stats;
    absl::StatusOr<MeshData> cut = terrain::CutFrictionOutlines(
        derived, request.friction_geojson(), from.terrain ? &*from.terrain : nullptr,
        "friction_geojson", &cut_stats, env.limits->max_vertices);
    if (ExceededLimit(cut.status())) return cut.status();
    if (!cut.ok()) {
      absl::string_view message = cut.status().message();
      absl::ConsumePrefix(&message, "friction_geojson: ");  // FieldError names it
      if (!absl::IsInvalidArgument(cut.status())) {
        return absl::Status(cut.status().code(), absl::StrCat("friction_geojson: ", message));
      }
      return FieldError("friction_geojson", message);
    }
    derived = *std::move(cut);
  }
  // A cut adds vertices and faces where the polygons cross the mesh: the mesh limits still hold.
  if (derived.vertex_count() > env.limits->max_vertices) {
    return LimitExceededError(
        Limit::kVertices,
        absl::StrCat("the cut mesh has ", derived.vertex_count(),
                     " vertices, more than --max_vertices ", env.limits->max_vertices));
  }
  if (derived.face_count() > env.limits->max_faces) {
    return LimitExceededError(
        Limit::kFaces, absl::StrCat("the cut mesh has ", derived.face_count(),
                                    " faces, more than --max_faces ", env.limits->max_faces));
  }
  if (env.cancel->IsCancelled()) return absl::CancelledError("derivation cancelled");
  const std::string id = ComputeMeshId(derived);
  auto candidate = std::make_shared<StoredMesh>();
  candidate->id = id;
  // Built unless stored already; a copy stored without the map (uploaded as a mesh file by a
  // client that derived it) gains it.
  if (env.store->NeedsBuild(id, from.terrain.has_value())) {
    absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(derived);
    if (!built.ok()) return FieldError("barrier", built.status().message());
    std::shared_ptr<const terrain::Dem> dem;
    if (from.terrain) {
      terrain::DemInfo info = *from.terrain;
      info.barrier_faces += barrier_faces;
      absl::StatusOr<terrain::Dem> grid = terrain::Dem::FromMesh(derived, std::move(info));
      if (!grid.ok()) return absl::InternalError(grid.status().message());
      dem = std::make_shared<const terrain::Dem>(*std::move(grid));
    }
    if (env.cancel->IsCancelled()) return absl::CancelledError("derivation cancelled");
    candidate = MakeStoredMesh(id, *std::move(built), std::move(dem));
    candidate->pinned = request.pin();
  }
  candidate->display_name = request.display_name();
  const std::string canonical =
      env.store->has_disk() && candidate->mesh != nullptr ? CanonicalMeshEncoding(derived) : "";
  absl::StatusOr<std::shared_ptr<const StoredMesh>> stored = env.store->Insert(
      std::move(candidate), canonical, env.limits->max_names_per_mesh, "display_name");
  if (!stored.ok()) return stored.status();
  MeshToProto(**stored, response);
  return absl::OkStatus();
}

}  // namespace geodex::server
