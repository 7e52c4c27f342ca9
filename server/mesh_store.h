#pragma once

// The mesh store: mesh id -> immutable preprocessed mesh, under a RAM byte budget with LRU eviction
// of unpinned meshes, optionally backed by the data directory (mesh_disk.h). Thread-safe. Queries
// hold a shared_ptr to the entry, so a delete or an eviction never disturbs a query in flight (the
// memory goes when the last query drops it).
//
// With a data directory every mesh is written to disk before it is acknowledged; the budget then
// evicts from memory only, and Get() loads an evicted (or not yet loaded) mesh back on first use.
// Without one, evicting a mesh forgets it.

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "geodex/locate.h"
#include "geodex/triangle_mesh.h"
#include "mesh_disk.h"
#include "mesh_record.h"

namespace geodex::server {

// One stored mesh; immutable once built. A record of a mesh that is only on disk has no `mesh`
// and `locator` (GetRecord); Get() always returns a loaded one.
struct StoredMesh : MeshRecord {
  std::shared_ptr<const TriangleMesh> mesh;
  std::shared_ptr<const SurfaceLocator> locator;  // points into *mesh
  // A DEM's mesh (`terrain` set): its grid, which drops map points onto the surface. Else null.
  std::shared_ptr<const terrain::Dem> dem;
};

// Builds a StoredMesh (mesh + locator) from a built mesh; fills memory_bytes and counts. `dem`:
// the DEM the mesh was made from, if any (its info becomes the record's terrain).
std::shared_ptr<StoredMesh> MakeStoredMesh(std::string id, TriangleMesh mesh,
                                           std::shared_ptr<const terrain::Dem> dem = nullptr);

class MeshStore {
 public:
  explicit MeshStore(uint64_t budget_bytes) : budget_bytes_(budget_bytes) {}

  // Backs the store with a data directory and registers the meshes its index found (not loaded).
  // Call once, before serving.
  void AttachDisk(MeshDisk disk, const MeshDisk::Index& index);
  bool has_disk() const { return disk_.has_value(); }

  // Adds `mesh` (built), persisting `canonical` (its canonical encoding) first when a data
  // directory is attached, and evicting least-recently-used unpinned meshes from memory as needed.
  // If a mesh with the same id is stored already, returns that one (re-uploads are idempotent; a
  // new alias is added to its names). Errors: ResourceExhausted when the mesh is larger than the
  // budget, cannot fit beside the pinned meshes, already has `max_names` names, or the disk is
  // full; InvalidArgument when the alias belongs to another mesh; Internal for other I/O errors.
  // `name_field` names the request field of the alias in errors.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> Insert(
      std::shared_ptr<StoredMesh> mesh, const std::string& canonical = "", uint32_t max_names = 16,
      const std::string& name_field = "metadata.display_name");

  // The mesh with this id or alias, loaded (from disk if needed; that can take a while: call it on
  // a compute thread). Marks it recently used. NotFound when unknown, DataLoss when its file does
  // not verify.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> Get(const std::string& id_or_alias);

  // What is known about a mesh without loading it (mesh/locator may be null). NotFound otherwise.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> GetRecord(const std::string& id_or_alias) const;

  // True if a mesh with this id is stored (in memory or on disk).
  bool Contains(const std::string& id) const;
  // True if storing mesh `id` needs it built: not stored yet, or stored without the DEM map a new
  // copy brings (`with_map`), which it then gains. Otherwise Insert of a bare record (id, names)
  // only adds the names.
  bool NeedsBuild(const std::string& id, bool with_map) const;

  // Removes the mesh with this id or alias, from memory and disk. NotFound otherwise.
  absl::Status Delete(const std::string& id_or_alias);

  // Up to `limit` records with id > `after`, ordered by id; `*more` tells whether more follow.
  std::vector<std::shared_ptr<const StoredMesh>> List(const std::string& after, size_t limit,
                                                      bool* more) const;

  uint64_t used_bytes() const;  // resident meshes
  uint64_t budget_bytes() const { return budget_bytes_; }
  size_t size() const;  // all meshes (resident or on disk)
  size_t resident_count() const;
  uint64_t evictions() const;
  uint64_t disk_loads() const;

 private:
  struct Slot {
    // The full entry when resident, else a record without mesh/locator.
    std::shared_ptr<const StoredMesh> mesh;
    std::list<std::string>::iterator lru;  // position in lru_ (valid when resident)
    bool resident = false;
  };
  // The slot for an id or alias, or nullptr.
  Slot* FindLocked(const std::string& id_or_alias);
  const Slot* FindLocked(const std::string& id_or_alias) const;
  // Removes the mesh entirely.
  void RemoveLocked(const std::string& id);
  // Drops a resident mesh from memory (disk-backed) or removes it (RAM only).
  void EvictLocked(const std::string& id);
  // Unpinned resident meshes to evict (oldest first) so that `bytes` more fit; error if impossible.
  absl::StatusOr<std::vector<std::string>> VictimsLocked(uint64_t bytes) const;
  // Makes `mesh` resident in a slot (new or existing record), evicting `victims`.
  std::shared_ptr<const StoredMesh> AdmitLocked(std::shared_ptr<const StoredMesh> mesh);

  const uint64_t budget_bytes_;
  std::optional<MeshDisk> disk_;
  mutable std::mutex
      mu_;  // (std::mutex: visible to ThreadSanitizer; members below are guarded by it)
  std::map<std::string, Slot> meshes_;                     // ordered by id for List
  absl::flat_hash_map<std::string, std::string> aliases_;  // alias -> id
  std::list<std::string> lru_;  // resident meshes, most recently used first
  uint64_t used_bytes_ = 0;
  uint64_t evictions_ = 0;
  uint64_t disk_loads_ = 0;
};

}  // namespace geodex::server
