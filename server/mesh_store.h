#pragma once

// The in-memory mesh store: mesh id -> immutable preprocessed mesh, under a RAM byte budget with
// LRU eviction of unpinned meshes. Thread-safe. Queries hold a shared_ptr to the entry, so a
// delete or an eviction never disturbs a query in flight (the memory goes when the last query
// drops it).

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "geodex/locate.h"
#include "geodex/triangle_mesh.h"

namespace geodex::server {

// One stored mesh; immutable once built.
struct StoredMesh {
  std::string id;            // SHA-256 hex (see mesh_id.h)
  std::string display_name;  // optional alias
  std::shared_ptr<const TriangleMesh> mesh;
  std::shared_ptr<const SurfaceLocator> locator;  // points into *mesh
  uint64_t vertex_count = 0;  // file vertices
  uint64_t face_count = 0;
  uint64_t upload_bytes = 0;
  uint64_t memory_bytes = 0;  // mesh + locator, counted against the budget
  bool pinned = false;
  absl::Time create_time;
};

// Builds a StoredMesh (mesh + locator) from a built mesh; fills memory_bytes and counts.
std::shared_ptr<StoredMesh> MakeStoredMesh(std::string id, TriangleMesh mesh);

class MeshStore {
 public:
  explicit MeshStore(uint64_t budget_bytes) : budget_bytes_(budget_bytes) {}

  // Adds `mesh`, evicting least-recently-used unpinned meshes as needed. If a mesh with the same id
  // is stored already, returns that one (re-uploads are idempotent; a new alias is added to it
  // when it has none). Errors: ResourceExhausted when the mesh is larger than the budget or cannot
  // fit beside the pinned meshes; InvalidArgument when the alias belongs to another mesh.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> Insert(std::shared_ptr<StoredMesh> mesh);

  // The mesh with this id or alias (marks it recently used). NotFound otherwise.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> Get(const std::string& id_or_alias);

  // True if a mesh with this id is stored (does not touch the LRU order).
  bool Contains(const std::string& id) const;

  // Removes the mesh with this id or alias. NotFound otherwise.
  absl::Status Delete(const std::string& id_or_alias);

  // Up to `limit` meshes with id > `after`, ordered by id; `*more` tells whether more follow.
  std::vector<std::shared_ptr<const StoredMesh>> List(const std::string& after, size_t limit,
                                                      bool* more) const;

  uint64_t used_bytes() const;
  uint64_t budget_bytes() const { return budget_bytes_; }
  size_t size() const;
  uint64_t evictions() const;

 private:
  struct Slot {
    std::shared_ptr<const StoredMesh> mesh;
    std::list<std::string>::iterator lru;  // position in lru_
  };
  // The slot for an id or alias, or nullptr.
  Slot* FindLocked(const std::string& id_or_alias) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void RemoveLocked(const std::string& id) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  const uint64_t budget_bytes_;
  mutable absl::Mutex mu_;
  std::map<std::string, Slot> meshes_ ABSL_GUARDED_BY(mu_);  // ordered by id for List
  absl::flat_hash_map<std::string, std::string> aliases_ ABSL_GUARDED_BY(mu_);  // alias -> id
  std::list<std::string> lru_ ABSL_GUARDED_BY(mu_);  // most recently used first
  uint64_t used_bytes_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t evictions_ ABSL_GUARDED_BY(mu_) = 0;
};

}  // namespace geodex::server
