// Mesh resources: GetMesh, ListMeshes, DeleteMesh (answered inline: map look-ups).

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "geodex/mesh_id.h"
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

}  // namespace geodex::server
