#include "ich/solve_workspace.h"

namespace geodex::ich {

void SolveWorkspace::Prepare(const TriangleMesh& mesh, bool with_links, bool with_split_owner) {
  const uint32_t nv = mesh.vertex_count();
  const uint32_t nf = mesh.face_count();
  const size_t nh = 3 * size_t{nf};
  if (vertices_ != nv || dist.size() != nv) {
    dist.assign(nv, kUnreachable);
    label.assign(nv, kNoIndex);
    origin.assign(nv, VertexOrigin{});
    straight_through.assign(nv, 0);
    vertex_is_target.assign(nv, 0);
    vertices_ = nv;
  }
  if (half_edges_ != nh || split.size() != nh) {
    split.assign(nh, SplitRecord{});
    split_owner.clear();
    half_edges_ = nh;
  }
  if (with_split_owner && split_owner.size() != nh) split_owner.assign(nh, SplitOwner{});
  if (faces_ != nf || face_target_head.size() != nf) {
    face_target_head.assign(nf, kNoIndex);
    faces_ = nf;
  }
  pool.Reset(with_links);
  ClearLists();
}

void SolveWorkspace::ClearLists() {
  touched_vertices.clear();
  touched_half_edges.clear();
  target_vertices.clear();
  target_faces.clear();
  face_target_next.clear();
  face_target_entry.clear();
}

void SolveWorkspace::Clear() {
  // Arrays a full field moved out are empty: Prepare refills them.
  if (dist.size() == vertices_ && label.size() == vertices_ && origin.size() == vertices_) {
    for (uint32_t v : touched_vertices) {
      dist[v] = kUnreachable;
      label[v] = kNoIndex;
      origin[v] = VertexOrigin{};
      straight_through[v] = 0;
    }
  } else {
    dist.clear();
    label.clear();
    origin.clear();
  }
  for (uint32_t v : target_vertices) vertex_is_target[v] = 0;
  const bool owners = split_owner.size() == split.size();
  for (uint32_t h : touched_half_edges) {
    split[h] = SplitRecord{};
    if (owners) split_owner[h] = SplitOwner{};
  }
  for (uint32_t f : target_faces) face_target_head[f] = kNoIndex;
  ClearLists();
  pool.Reset(pool.with_links());
}

uint64_t SolveWorkspace::MeshArrayBytes() const {
  auto bytes = [](const auto& v) { return uint64_t{v.capacity()} * sizeof(v[0]); };
  return bytes(dist) + bytes(label) + bytes(origin) + bytes(straight_through) +
         bytes(vertex_is_target) + bytes(split) + bytes(split_owner) + bytes(face_target_head) +
         bytes(touched_vertices) + bytes(touched_half_edges);
}

std::unique_ptr<SolveWorkspace> WorkspaceCache::Acquire() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!idle_.empty()) {
      std::unique_ptr<SolveWorkspace> ws = std::move(idle_.back());
      idle_.pop_back();
      return ws;
    }
  }
  return std::make_unique<SolveWorkspace>();
}

void WorkspaceCache::Release(std::unique_ptr<SolveWorkspace> ws) {
  ws->Clear();
  if (ws->WorkBytes() > ws->MeshArrayBytes()) ws->ReleaseWorkMemory();
  std::lock_guard<std::mutex> lock(mu_);
  idle_.push_back(std::move(ws));
}

uint64_t WorkspaceCache::IdleBytes() {
  std::lock_guard<std::mutex> lock(mu_);
  uint64_t bytes = 0;
  for (const auto& ws : idle_) bytes += ws->MeshArrayBytes() + ws->WorkBytes();
  return bytes;
}

}  // namespace geodex::ich
