#include "mesh_store.h"

#include <utility>

#include "absl/strings/str_cat.h"

namespace geodex::server {

std::shared_ptr<StoredMesh> MakeStoredMesh(std::string id, TriangleMesh mesh) {
  auto stored = std::make_shared<StoredMesh>();
  stored->id = std::move(id);
  auto built = std::make_shared<const TriangleMesh>(std::move(mesh));
  stored->locator = std::make_shared<const SurfaceLocator>(*built);
  stored->mesh = std::move(built);
  stored->vertex_count = stored->mesh->file_vertex_count();
  stored->face_count = stored->mesh->face_count();
  stored->memory_bytes = stored->mesh->MemoryBytes() + stored->locator->MemoryBytes();
  stored->create_time = absl::Now();
  return stored;
}

absl::StatusOr<std::shared_ptr<const StoredMesh>> MeshStore::Insert(
    std::shared_ptr<StoredMesh> mesh) {
  absl::MutexLock lock(&mu_);
  if (!mesh->display_name.empty()) {
    auto alias = aliases_.find(mesh->display_name);
    if (alias != aliases_.end() && alias->second != mesh->id) {
      return absl::InvalidArgumentError(absl::StrCat("metadata.display_name: \"",
                                                     mesh->display_name,
                                                     "\" already names mesh ", alias->second));
    }
  }
  auto existing = meshes_.find(mesh->id);
  if (existing != meshes_.end()) {
    Slot& slot = existing->second;
    lru_.splice(lru_.begin(), lru_, slot.lru);
    if (!mesh->display_name.empty() && slot.mesh->display_name.empty()) {
      auto updated = std::make_shared<StoredMesh>(*slot.mesh);
      updated->display_name = mesh->display_name;
      aliases_[mesh->display_name] = mesh->id;
      slot.mesh = std::move(updated);
    }
    return slot.mesh;
  }
  if (mesh->memory_bytes > budget_bytes_) {
    return absl::ResourceExhaustedError(
        absl::StrCat("mesh needs ", mesh->memory_bytes, " bytes of memory, more than the whole ",
                     "mesh budget (--mesh_budget_bytes=", budget_bytes_, ")"));
  }
  // Which unpinned meshes (oldest first) would have to go; fail without evicting if not enough.
  std::vector<std::string> victims;
  uint64_t freed = 0;
  for (auto it = lru_.rbegin();
       it != lru_.rend() && used_bytes_ - freed + mesh->memory_bytes > budget_bytes_; ++it) {
    const Slot& slot = meshes_.at(*it);
    if (slot.mesh->pinned) continue;
    victims.push_back(*it);
    freed += slot.mesh->memory_bytes;
  }
  if (used_bytes_ - freed + mesh->memory_bytes > budget_bytes_) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "mesh needs ", mesh->memory_bytes, " bytes of memory but pinned meshes hold ",
        used_bytes_ - freed, " of the ", budget_bytes_, " byte budget (--mesh_budget_bytes)"));
  }
  for (const std::string& id : victims) {
    RemoveLocked(id);
    ++evictions_;
  }
  lru_.push_front(mesh->id);
  used_bytes_ += mesh->memory_bytes;
  if (!mesh->display_name.empty()) aliases_[mesh->display_name] = mesh->id;
  std::string id = mesh->id;
  Slot& slot = meshes_[id];
  slot.mesh = std::move(mesh);
  slot.lru = lru_.begin();
  return slot.mesh;
}

MeshStore::Slot* MeshStore::FindLocked(const std::string& id_or_alias) {
  auto it = meshes_.find(id_or_alias);
  if (it != meshes_.end()) return &it->second;
  auto alias = aliases_.find(id_or_alias);
  if (alias == aliases_.end()) return nullptr;
  it = meshes_.find(alias->second);
  return it == meshes_.end() ? nullptr : &it->second;
}

void MeshStore::RemoveLocked(const std::string& id) {
  auto it = meshes_.find(id);
  if (it == meshes_.end()) return;
  const StoredMesh& mesh = *it->second.mesh;
  if (!mesh.display_name.empty()) aliases_.erase(mesh.display_name);
  used_bytes_ -= mesh.memory_bytes;
  lru_.erase(it->second.lru);
  meshes_.erase(it);
}

absl::StatusOr<std::shared_ptr<const StoredMesh>> MeshStore::Get(const std::string& id_or_alias) {
  absl::MutexLock lock(&mu_);
  Slot* slot = FindLocked(id_or_alias);
  if (slot == nullptr) return absl::NotFoundError(absl::StrCat("mesh \"", id_or_alias, "\" not found"));
  lru_.splice(lru_.begin(), lru_, slot->lru);
  return slot->mesh;
}

bool MeshStore::Contains(const std::string& id) const {
  absl::MutexLock lock(&mu_);
  return meshes_.contains(id);
}

absl::Status MeshStore::Delete(const std::string& id_or_alias) {
  absl::MutexLock lock(&mu_);
  Slot* slot = FindLocked(id_or_alias);
  if (slot == nullptr) return absl::NotFoundError(absl::StrCat("mesh \"", id_or_alias, "\" not found"));
  RemoveLocked(std::string(slot->mesh->id));
  return absl::OkStatus();
}

std::vector<std::shared_ptr<const StoredMesh>> MeshStore::List(const std::string& after,
                                                               size_t limit, bool* more) const {
  absl::MutexLock lock(&mu_);
  std::vector<std::shared_ptr<const StoredMesh>> out;
  auto it = after.empty() ? meshes_.begin() : meshes_.upper_bound(after);
  for (; it != meshes_.end() && out.size() < limit; ++it) out.push_back(it->second.mesh);
  *more = it != meshes_.end();
  return out;
}

uint64_t MeshStore::used_bytes() const {
  absl::MutexLock lock(&mu_);
  return used_bytes_;
}

size_t MeshStore::size() const {
  absl::MutexLock lock(&mu_);
  return meshes_.size();
}

uint64_t MeshStore::evictions() const {
  absl::MutexLock lock(&mu_);
  return evictions_;
}

}  // namespace geodex::server
