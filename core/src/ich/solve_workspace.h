#pragma once

// What a solve writes per vertex and per half-edge, kept between solves so that a targeted solve
// (a path, a matrix row, distances at points) costs what it touches, not O(V + F) of set-up.

#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "geodex/distance_field.h"
#include "geodex/triangle_mesh.h"
#include "ich/window.h"

namespace geodex::ich {

// Every array is in its default state between solves (distances +inf, no labels, no Lemma 1
// records, no targets): a solve records the entries it changes, and Clear() restores just those.
class SolveWorkspace {
 public:
  // Makes every array fit `mesh` in its default state. O(V + F) only when one does not fit
  // (first use, a mesh of another size, or a full field that moved its arrays out).
  void Prepare(const TriangleMesh& mesh, bool with_links, bool with_split_owner);
  // Restores what the last solve touched: cost proportional to that solve's work.
  void Clear();
  // Idle memory beyond the per-mesh arrays (the window pool and queue grow with the work done).
  uint64_t WorkBytes() const { return pool.CapacityBytes() + queue.CapacityBytes(); }
  uint64_t MeshArrayBytes() const;
  void ReleaseWorkMemory() {
    pool.ReleaseMemory();
    queue.ReleaseMemory();
    std::vector<uint32_t>().swap(scratch);
  }

  // Per vertex (internal ids).
  std::vector<double> dist;
  std::vector<uint32_t> label;
  std::vector<VertexOrigin> origin;
  // Which sides of its best incoming ray continue straight (bit 1 left, bit 2 right).
  std::vector<uint8_t> straight_through;
  std::vector<uint8_t> vertex_is_target;
  // Per half-edge: Lemma 1's records (the owners only for the paper's tree).
  HugeVector<SplitRecord> split;
  HugeVector<SplitOwner> split_owner;
  // Per face: the first (target, placement) entry of a targeted solve.
  std::vector<uint32_t> face_target_head;
  std::vector<uint32_t> face_target_next;
  std::vector<std::pair<uint32_t, uint32_t>> face_target_entry;  // entry -> (target, placement)

  WindowPool pool;
  WindowQueue queue;
  std::vector<uint32_t> scratch;  // subtree deletion's stack

  // What the current solve changed, for Clear(). A vertex enters once (when its distance first
  // becomes finite), a half-edge once (its first Lemma 1 record): bounded by the mesh.
  std::vector<uint32_t> touched_vertices;
  std::vector<uint32_t> touched_half_edges;
  std::vector<uint32_t> target_vertices;
  std::vector<uint32_t> target_faces;

 private:
  void ClearLists();  // the touched and target lists, and the target entries

  uint32_t vertices_ = 0;  // the sizes Prepare made the arrays
  size_t half_edges_ = 0;
  uint32_t faces_ = 0;
};

// A mesh's idle workspaces, shared by every thread that solves on it: one lock per solve, none
// per window. It holds at most as many workspaces as solves ever ran at once on the mesh, and
// they go with the mesh.
class WorkspaceCache {
 public:
  std::unique_ptr<SolveWorkspace> Acquire();
  // Clears `ws` and keeps it; a window pool and queue larger than the per-mesh arrays (a big
  // solve) are released first, so what stays idle grows with the mesh, not with past work.
  void Release(std::unique_ptr<SolveWorkspace> ws);
  uint64_t IdleBytes();

 private:
  std::mutex mu_;
  std::vector<std::unique_ptr<SolveWorkspace>> idle_;
};

}  // namespace geodex::ich
