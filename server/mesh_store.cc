#include "mesh_store.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "geodex/mesh_id.h"
#include "status_convert.h"

namespace geodex::server {

std::shared_ptr<StoredMesh> MakeStoredMesh(std::string id, TriangleMesh mesh,
                                           std::shared_ptr<const terrain::Dem> dem) {
  auto stored = std::make_shared<StoredMesh>();
  stored->id = std::move(id);
  auto built = std::make_shared<const TriangleMesh>(std::move(mesh));
  stored->locator = std::make_shared<const SurfaceLocator>(*built);
  stored->mesh = std::move(built);
  stored->vertex_count = stored->mesh->file_vertex_count();
  stored->face_count = stored->mesh->face_count();
  stored->memory_bytes = stored->mesh->MemoryBytes() + stored->locator->MemoryBytes();
  stored->create_time = absl::Now();
  stored->summary = Summarize(*stored->mesh);
  if (dem != nullptr) {
    stored->memory_bytes += dem->MemoryBytes();
    stored->terrain = dem->info();
    stored->dem = std::move(dem);
  }
  return stored;
}

namespace {

// The record of a resident mesh: the same fields, no mesh.
std::shared_ptr<const StoredMesh> Strip(const StoredMesh& mesh) {
  auto record = std::make_shared<StoredMesh>(mesh);
  record->mesh.reset();
  record->locator.reset();
  record->dem.reset();
  return record;
}

}  // namespace

void MeshStore::AttachDisk(MeshDisk disk, const MeshDisk::Index& index) {
  std::lock_guard<std::mutex> lock(mu_);
  disk_.emplace(std::move(disk));
  for (const MeshDisk::IndexEntry& entry : index.meshes) {
    auto record = std::make_shared<StoredMesh>();
    static_cast<MeshRecord&>(*record) = entry.header;
    if (!record->display_name.empty()) {
      // Aliases are unique when written; a clash means hand-copied files: first one wins.
      if (aliases_.contains(record->display_name)) {
        record->display_name.clear();
      } else {
        aliases_[record->display_name] = entry.id;
      }
    }
    std::vector<std::string> kept;
    for (const std::string& alias : record->aliases) {
      if (!alias.empty() && !aliases_.contains(alias)) {
        aliases_[alias] = entry.id;
        kept.push_back(alias);
      }
    }
    record->aliases = std::move(kept);
    meshes_[entry.id].mesh = std::move(record);
  }
}

absl::StatusOr<std::vector<std::string>> MeshStore::VictimsLocked(uint64_t bytes) const {
  if (bytes > budget_bytes_) {
    return ServerLimitError(
        "mesh_budget_bytes",
        absl::StrCat("mesh needs ", bytes, " bytes of memory, more than the whole ",
                     "mesh budget (--mesh_budget_bytes=", budget_bytes_, ")"));
  }
  std::vector<std::string> victims;
  uint64_t freed = 0;
  for (auto it = lru_.rbegin(); it != lru_.rend() && used_bytes_ - freed + bytes > budget_bytes_;
       ++it) {
    const Slot& slot = meshes_.at(*it);
    if (slot.mesh->pinned) continue;
    victims.push_back(*it);
    freed += slot.mesh->memory_bytes;
  }
  if (used_bytes_ - freed + bytes > budget_bytes_) {
    return ServerLimitError(
        "mesh_budget_bytes",
        absl::StrCat("mesh needs ", bytes, " bytes of memory but pinned meshes hold ",
                     used_bytes_ - freed, " of the ", budget_bytes_,
                     " byte budget (--mesh_budget_bytes)"));
  }
  return victims;
}

std::shared_ptr<const StoredMesh> MeshStore::AdmitLocked(std::shared_ptr<const StoredMesh> mesh) {
  const std::string id = mesh->id;
  Slot& slot = meshes_[id];
  if (!mesh->display_name.empty()) aliases_[mesh->display_name] = id;
  lru_.push_front(id);
  used_bytes_ += mesh->memory_bytes;
  slot.mesh = std::move(mesh);
  slot.lru = lru_.begin();
  slot.resident = true;
  return slot.mesh;
}

absl::StatusOr<std::shared_ptr<const StoredMesh>> MeshStore::Insert(
    std::shared_ptr<StoredMesh> mesh, const std::string& canonical, uint32_t max_names,
    const std::string& name_field) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!mesh->display_name.empty()) {
      auto alias = aliases_.find(mesh->display_name);
      if (alias != aliases_.end() && alias->second != mesh->id) {
        return FieldError(name_field, absl::StrCat("\"", mesh->display_name,
                                                   "\" already names mesh ", alias->second));
      }
    }
    auto existing = meshes_.find(mesh->id);
    if (existing != meshes_.end()) {
      Slot& slot = existing->second;
      if (slot.resident) lru_.splice(lru_.begin(), lru_, slot.lru);
      const std::string& name = mesh->display_name;
      const StoredMesh& old = *slot.mesh;
      const bool known =
          name.empty() || old.display_name == name ||
          std::find(old.aliases.begin(), old.aliases.end(), name) != old.aliases.end();
      // The same mesh uploaded as its DEM: the record gains the map (and, resident, the grid).
      const bool gains_terrain = !old.terrain && mesh->terrain && mesh->dem != nullptr;
      if (gains_terrain) {
        auto updated = std::make_shared<StoredMesh>(old);
        updated->terrain = mesh->terrain;
        // Resident, it holds the grid too: room is made for it as for any mesh (not by evicting
        // this one, just used), before anything is written.
        const uint64_t extra = slot.resident ? mesh->dem->MemoryBytes() : 0;
        std::vector<std::string> victims;
        if (extra > 0) {
          absl::StatusOr<std::vector<std::string>> room = VictimsLocked(extra);
          if (!room.ok()) return room.status();
          for (std::string& id : *room) {
            if (id != mesh->id) victims.push_back(std::move(id));
          }
          updated->dem = mesh->dem;
          updated->memory_bytes += extra;
        }
        if (disk_) {
          if (absl::Status s = disk_->UpdateHeader(*updated); !s.ok()) return s;
        }
        for (const std::string& id : victims) EvictLocked(id);
        used_bytes_ += extra;
        slot.mesh = std::move(updated);
      }
      const StoredMesh& current = *slot.mesh;
      if (!known) {
        const size_t names = (current.display_name.empty() ? 0 : 1) + current.aliases.size();
        if (names >= max_names) {
          return ServerLimitError(
              "max_names_per_mesh",
              absl::StrCat(name_field, ": mesh ", mesh->id, " already has ", names,
                           " names, the most a mesh may have (--max_names_per_mesh=", max_names,
                           ")"));
        }
        auto updated = std::make_shared<StoredMesh>(current);
        if (updated->display_name.empty()) {
          updated->display_name = name;
        } else {
          updated->aliases.push_back(name);
        }
        if (disk_) {
          if (absl::Status s = disk_->UpdateHeader(*updated); !s.ok()) return s;
        }
        aliases_[mesh->display_name] = mesh->id;
        slot.mesh = std::move(updated);
      }
      return slot.mesh;
    }
    if (mesh->mesh == nullptr) {  // a re-upload whose stored mesh was deleted meanwhile
      return absl::AbortedError(
          absl::StrCat("mesh ", mesh->id, " was deleted during the upload; retry"));
    }
    // Fail early, before writing anything, when the mesh can never fit.
    if (absl::StatusOr<std::vector<std::string>> victims = VictimsLocked(mesh->memory_bytes);
        !victims.ok()) {
      return victims.status();
    }
  }
  // Persist before acknowledging (outside the lock: writing a large mesh takes a while).
  if (disk_) {
    if (absl::Status s = disk_->Write(*mesh, canonical); !s.ok()) return s;
  }
  std::lock_guard<std::mutex> lock(mu_);
  if (auto existing = meshes_.find(mesh->id);
      existing != meshes_.end() && existing->second.resident) {
    return existing->second.mesh;  // a concurrent upload of the same mesh won
  }
  absl::StatusOr<std::vector<std::string>> victims = VictimsLocked(mesh->memory_bytes);
  if (!victims.ok()) return victims.status();
  for (const std::string& id : *victims) EvictLocked(id);
  return AdmitLocked(std::move(mesh));
}

MeshStore::Slot* MeshStore::FindLocked(const std::string& id_or_alias) {
  auto it = meshes_.find(id_or_alias);
  if (it != meshes_.end()) return &it->second;
  auto alias = aliases_.find(id_or_alias);
  if (alias == aliases_.end()) return nullptr;
  it = meshes_.find(alias->second);
  return it == meshes_.end() ? nullptr : &it->second;
}

const MeshStore::Slot* MeshStore::FindLocked(const std::string& id_or_alias) const {
  return const_cast<MeshStore*>(this)->FindLocked(id_or_alias);
}

void MeshStore::RemoveLocked(const std::string& id) {
  auto it = meshes_.find(id);
  if (it == meshes_.end()) return;
  const StoredMesh& mesh = *it->second.mesh;
  if (!mesh.display_name.empty()) aliases_.erase(mesh.display_name);
  for (const std::string& alias : mesh.aliases) aliases_.erase(alias);
  if (it->second.resident) {
    used_bytes_ -= mesh.memory_bytes;
    lru_.erase(it->second.lru);
  }
  meshes_.erase(it);
}

void MeshStore::EvictLocked(const std::string& id) {
  ++evictions_;
  if (!disk_) {
    RemoveLocked(id);
    return;
  }
  Slot& slot = meshes_.at(id);
  used_bytes_ -= slot.mesh->memory_bytes;
  lru_.erase(slot.lru);
  slot.resident = false;
  slot.mesh = Strip(*slot.mesh);
}

absl::StatusOr<std::shared_ptr<const StoredMesh>> MeshStore::Get(const std::string& id_or_alias) {
  std::shared_ptr<const StoredMesh> record;
  {
    std::lock_guard<std::mutex> lock(mu_);
    Slot* slot = FindLocked(id_or_alias);
    if (slot == nullptr) {
      return absl::NotFoundError(absl::StrCat("mesh \"", id_or_alias, "\" not found"));
    }
    if (slot->resident) {
      lru_.splice(lru_.begin(), lru_, slot->lru);
      return slot->mesh;
    }
    record = slot->mesh;
  }
  // Load from disk without holding the lock. Two concurrent first uses may both load; the second
  // to finish takes the first's entry.
  MeshRecord header;
  std::string canonical;
  if (absl::Status s = disk_->Read(record->id, &header, &canonical); !s.ok()) return s;
  absl::StatusOr<MeshData> data = DecodeCanonicalMesh(canonical);
  if (!data.ok()) {
    return absl::DataLossError(
        absl::StrCat("stored mesh meshes/", record->id, ": ", data.status().message()));
  }
  canonical.clear();
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(*data);
  if (!built.ok()) {
    return absl::DataLossError(
        absl::StrCat("stored mesh meshes/", record->id, ": ", built.status().message()));
  }
  std::shared_ptr<const terrain::Dem> dem;
  if (header.terrain) {
    absl::StatusOr<terrain::Dem> grid = terrain::Dem::FromMesh(*std::move(data), *header.terrain);
    if (!grid.ok()) {
      return absl::DataLossError(
          absl::StrCat("stored mesh meshes/", record->id, ": ", grid.status().message()));
    }
    dem = std::make_shared<const terrain::Dem>(*std::move(grid));
  }
  std::shared_ptr<StoredMesh> loaded =
      MakeStoredMesh(record->id, *std::move(built), std::move(dem));
  loaded->display_name = record->display_name;
  loaded->aliases = record->aliases;
  loaded->pinned = record->pinned;
  loaded->upload_bytes = record->upload_bytes;
  loaded->create_time = record->create_time;

  std::unique_lock<std::mutex> lock(mu_);
  auto it = meshes_.find(record->id);
  if (it == meshes_.end()) {
    return absl::NotFoundError(absl::StrCat("mesh \"", id_or_alias, "\" was deleted"));
  }
  if (!it->second.resident && it->second.mesh->terrain && !loaded->terrain) {
    // The record gained its map while this load read the older header: read it again.
    lock.unlock();
    return Get(id_or_alias);
  }
  if (it->second.resident) {
    lru_.splice(lru_.begin(), lru_, it->second.lru);
    return it->second.mesh;
  }
  loaded->display_name = it->second.mesh->display_name;  // an alias may have been added meanwhile
  loaded->aliases = it->second.mesh->aliases;
  absl::StatusOr<std::vector<std::string>> victims = VictimsLocked(loaded->memory_bytes);
  if (!victims.ok()) return victims.status();
  for (const std::string& id : *victims) EvictLocked(id);
  ++disk_loads_;
  return AdmitLocked(std::move(loaded));
}

absl::StatusOr<std::shared_ptr<const StoredMesh>> MeshStore::GetRecord(
    const std::string& id_or_alias) const {
  std::lock_guard<std::mutex> lock(mu_);
  const Slot* slot = FindLocked(id_or_alias);
  if (slot == nullptr) {
    return absl::NotFoundError(absl::StrCat("mesh \"", id_or_alias, "\" not found"));
  }
  return slot->mesh;
}

bool MeshStore::Contains(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mu_);
  return meshes_.contains(id);
}

bool MeshStore::NeedsBuild(const std::string& id, bool with_map) const {
  absl::StatusOr<std::shared_ptr<const StoredMesh>> known = GetRecord(id);
  return !known.ok() || (with_map && !(*known)->terrain.has_value());
}

absl::Status MeshStore::Delete(const std::string& id_or_alias) {
  std::lock_guard<std::mutex> lock(mu_);
  Slot* slot = FindLocked(id_or_alias);
  if (slot == nullptr) {
    return absl::NotFoundError(absl::StrCat("mesh \"", id_or_alias, "\" not found"));
  }
  const std::string id = slot->mesh->id;
  if (disk_) {
    if (absl::Status s = disk_->Remove(id); !s.ok()) return s;
  }
  RemoveLocked(id);
  return absl::OkStatus();
}

std::vector<std::shared_ptr<const StoredMesh>> MeshStore::List(const std::string& after,
                                                               size_t limit, bool* more) const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<std::shared_ptr<const StoredMesh>> out;
  auto it = after.empty() ? meshes_.begin() : meshes_.upper_bound(after);
  for (; it != meshes_.end() && out.size() < limit; ++it) out.push_back(it->second.mesh);
  *more = it != meshes_.end();
  return out;
}

uint64_t MeshStore::used_bytes() const {
  std::lock_guard<std::mutex> lock(mu_);
  return used_bytes_;
}

size_t MeshStore::size() const {
  std::lock_guard<std::mutex> lock(mu_);
  return meshes_.size();
}

size_t MeshStore::resident_count() const {
  std::lock_guard<std::mutex> lock(mu_);
  return lru_.size();
}

uint64_t MeshStore::evictions() const {
  std::lock_guard<std::mutex> lock(mu_);
  return evictions_;
}

uint64_t MeshStore::disk_loads() const {
  std::lock_guard<std::mutex> lock(mu_);
  return disk_loads_;
}

}  // namespace geodex::server
