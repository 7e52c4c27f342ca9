#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/mesh_data.h"

namespace geodex {

namespace ich {
class WorkspaceCache;  // private to core (src/ich/solve_workspace.h)
}

inline constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();

// How TriangleMesh::Build treats messy input.
struct MeshBuildOptions {
  // Reject non-manifold edges/vertices and inconsistent orientation instead of repairing them
  // (cutting at non-manifold junctions, re-orienting per component).
  bool strict = false;
};

// What Build found in the file (all counts refer to the file's vertices and faces).
struct MeshReport {
  uint64_t file_vertices = 0;
  uint64_t file_faces = 0;
  uint64_t boundary_edges = 0;
  uint64_t boundary_loops = 0;
  uint64_t components = 0;  // connected pieces of faces after cutting at non-manifold vertices
  uint64_t vertex_connected_components = 0;  // pieces joined through any shared vertex
  uint64_t isolated_vertices = 0;            // vertices referenced by no face
  uint64_t non_manifold_edges = 0;           // edges shared by more than two faces (cut)
  uint64_t non_manifold_vertices = 0;        // file vertices split into several internal copies
  uint64_t degenerate_faces = 0;             // zero-area faces (no window crosses them)
  uint64_t flipped_faces = 0;                // faces re-oriented to agree with their component
  uint64_t orientation_cuts = 0;             // edges cut because no consistent orientation exists
  uint64_t saddle_vertices = 0;  // interior vertices with angle sum >= 2*pi (within round-off)
  uint64_t boundary_vertices = 0;
};

class TriangleMesh;

// What `geodex info` and geodexd's Mesh resource say about a built mesh: its report and geometry.
struct MeshSummary {
  MeshReport report;
  uint64_t internal_vertices = 0;
  double mean_edge_length = 0, max_edge_length = 0;
  std::array<double, 3> bbox_min{}, bbox_max{};  // file coordinates
  uint64_t bytes = 0;                            // TriangleMesh::MemoryBytes
};
MeshSummary Summarize(const TriangleMesh& mesh);

// An immutable triangle mesh with everything the geodesic engine reads precomputed.
//
// Internal vertex ids: 0..file_vertex_count()-1 are the file's vertices; a file vertex that is
// non-manifold (several fans of faces meet only at it) keeps its id for its first fan and gets a
// new internal id >= file_vertex_count() per further fan, so that paths never cross such
// junctions. FileVertex() maps back. Faces keep the file's order; a face may have its 2nd and 3rd
// corners swapped (FaceFlipped) so that each component is consistently oriented.
//
// Half-edge h = 3*f + k runs from corner k to corner (k+1)%3 of face f; its frame puts the start at
// (0,0), the end at (length,0) and the opposite corner at (opp_x, opp_y) with opp_y > 0.
//
// Positions are recentred on the bounding-box centre (large georeferenced coordinates keep their
// precision); Center() restores file coordinates.
class TriangleMesh {
 public:
  // Validates and builds. Errors (InvalidArgument, naming the face/vertex): empty mesh, face index
  // out of range, a face repeating a vertex, NaN/Inf coordinates; in strict mode also non-manifold
  // or inconsistently oriented input.
  static absl::StatusOr<TriangleMesh> Build(const MeshData& data,
                                            const MeshBuildOptions& options = {});
  // The mesh as file data again: the file's vertices (recentred positions plus the centre, within
  // a few ulps of the file's values) and faces (file vertex ids, the file's corner order).
  MeshData ToMeshData() const;

  TriangleMesh(TriangleMesh&&) = default;
  TriangleMesh& operator=(TriangleMesh&&) = default;

  // --- sizes and mapping ---
  uint32_t vertex_count() const { return static_cast<uint32_t>(vertex_flags_.size()); }
  uint32_t face_count() const { return static_cast<uint32_t>(faces_.size() / 3); }
  uint32_t file_vertex_count() const { return file_vertex_count_; }
  uint32_t FileVertex(uint32_t v) const {
    return v < file_vertex_count_ ? v : copy_of_[v - file_vertex_count_];
  }
  // Internal copies (beyond the file vertex itself) of file vertex v; empty for manifold vertices.
  const std::vector<uint32_t>& copy_of() const { return copy_of_; }

  // --- geometry ---
  const std::array<double, 3>& Center() const { return center_; }
  std::array<double, 3> Position(uint32_t v) const {
    return {positions_[3 * v], positions_[3 * v + 1], positions_[3 * v + 2]};
  }
  const double* positions() const { return positions_.data(); }  // recentred, 3 per vertex
  uint32_t FaceVertex(uint32_t f, int k) const { return faces_[3 * f + k]; }
  const uint32_t* faces() const { return faces_.data(); }
  bool FaceFlipped(uint32_t f) const { return face_flags_[f] & kFaceFlipped; }
  // The one place that knows the two corner orders: internal corners 1 and 2 of a flipped face are
  // the file's corners 2 and 1. Swaps per-corner values (barycentrics, corner ids) from either
  // order into the other; it is its own inverse.
  template <typename T>
  void SwapCornerOrder(uint32_t f, std::array<T, 3>* per_corner) const {
    if (FaceFlipped(f)) std::swap((*per_corner)[1], (*per_corner)[2]);
  }
  // File vertex ids of face f's corners, in the file's corner order.
  std::array<uint32_t, 3> FileCorners(uint32_t f) const {
    std::array<uint32_t, 3> c{FileVertex(FaceVertex(f, 0)), FileVertex(FaceVertex(f, 1)),
                              FileVertex(FaceVertex(f, 2))};
    SwapCornerOrder(f, &c);
    return c;
  }
  bool FaceDegenerate(uint32_t f) const { return face_flags_[f] & kFaceDegenerate; }

  // --- half-edges (the engine's inner loop reads only these) ---
  static uint32_t FaceOf(uint32_t h) { return h / 3; }
  static uint32_t Next(uint32_t h) { return h - h % 3 + (h % 3 + 1) % 3; }
  static uint32_t Prev(uint32_t h) { return h - h % 3 + (h % 3 + 2) % 3; }
  uint32_t Twin(uint32_t h) const { return half_edges_[h].twin; }  // kNoIndex on a boundary
  uint32_t From(uint32_t h) const { return half_edges_[h].from; }
  uint32_t To(uint32_t h) const { return half_edges_[Next(h)].from; }
  uint32_t Opposite(uint32_t h) const { return half_edges_[Prev(h)].from; }
  double Length(uint32_t h) const { return half_edges_[h].length; }
  double OppX(uint32_t h) const { return half_edges_[h].opp_x; }
  double OppY(uint32_t h) const { return half_edges_[h].opp_y; }
  // Everything above for one half-edge in one 32-byte record; a face's three records are
  // contiguous (96 bytes), so the engine touches at most two cache lines per face.
  struct alignas(32) HalfEdge {
    double length, opp_x, opp_y;
    uint32_t twin;  // kNoIndex on a boundary
    uint32_t from;  // = From(h); To(h) and Opposite(h) are the next/previous records' `from`
  };
  const HalfEdge& HalfEdgeRecord(uint32_t h) const { return half_edges_[h]; }
  const HalfEdge* half_edges() const { return half_edges_.data(); }
  double CornerAngle(uint32_t corner) const { return corner_angle_[corner]; }

  // --- vertices ---
  double AngleSum(uint32_t v) const { return angle_sum_[v]; }
  bool IsSaddle(uint32_t v) const { return vertex_flags_[v] & kSaddle; }
  bool IsBoundary(uint32_t v) const { return vertex_flags_[v] & kBoundary; }
  bool IsIsolated(uint32_t v) const { return vertex_flags_[v] & kIsolated; }
  // Paths may bend here: saddle, boundary, or touching a degenerate face (ICH pseudo-source).
  bool IsPseudoSourceCandidate(uint32_t v) const { return vertex_flags_[v] & kPseudoSource; }
  uint32_t Component(uint32_t v) const { return component_[v]; }
  // True for an interior vertex whose faces close a full fan, none degenerate: only there does
  // CornerStartAngle() give a consistent angular coordinate.
  bool HasClosedFan(uint32_t v) const { return vertex_flags_[v] & kClosedFan; }
  // For a vertex with a closed fan: the counter-clockwise angle, from the vertex's reference edge,
  // of the corner's first edge (From(c) -> To(c)); the corner spans [start, start + angle).
  double CornerStartAngle(uint32_t corner) const { return corner_start_angle_[corner]; }
  // Corners (3*f+k) at vertex v, in no particular order.
  const uint32_t* CornersBegin(uint32_t v) const { return &vertex_corners_[corner_offsets_[v]]; }
  const uint32_t* CornersEnd(uint32_t v) const { return &vertex_corners_[corner_offsets_[v + 1]]; }
  // Edge neighbours (unique) with edge lengths, including edges of degenerate faces.
  uint32_t NeighborBegin(uint32_t v) const { return neighbor_offsets_[v]; }
  uint32_t NeighborEnd(uint32_t v) const { return neighbor_offsets_[v + 1]; }
  uint32_t NeighborVertex(uint32_t i) const { return neighbors_[i]; }
  double NeighborLength(uint32_t i) const { return neighbor_length_[i]; }

  // --- summary ---
  const MeshReport& report() const { return report_; }
  const std::array<double, 3>& BoundsMin() const { return bounds_min_; }  // file coordinates
  const std::array<double, 3>& BoundsMax() const { return bounds_max_; }
  double MeanEdgeLength() const { return mean_edge_length_; }
  double MaxEdgeLength() const { return max_edge_length_; }
  uint64_t MemoryBytes() const;
  // The engine's idle per-solve arrays, reused so a targeted solve costs what it touches (null in
  // a moved-from mesh). Thread-safe; not counted in MemoryBytes (at most one per concurrent solve).
  ich::WorkspaceCache* workspaces() const { return workspaces_.get(); }

 private:
  TriangleMesh() = default;

  enum : uint8_t { kFaceFlipped = 1, kFaceDegenerate = 2 };
  enum : uint8_t {
    kSaddle = 1,
    kBoundary = 2,
    kIsolated = 4,
    kPseudoSource = 8,
    kTouchesDegenerate = 16,
    kClosedFan = 32
  };

  friend class MeshBuilder;

  uint32_t file_vertex_count_ = 0;
  std::array<double, 3> center_{};
  std::array<double, 3> bounds_min_{}, bounds_max_{};
  std::vector<double> positions_;
  std::vector<uint32_t> faces_;
  std::vector<uint8_t> face_flags_;
  std::vector<uint32_t> copy_of_;
  std::vector<HalfEdge> half_edges_;
  std::vector<double> corner_angle_, corner_start_angle_;
  std::vector<double> angle_sum_;
  std::vector<uint8_t> vertex_flags_;
  std::vector<uint32_t> component_;
  std::vector<uint32_t> corner_offsets_, vertex_corners_;
  std::vector<uint32_t> neighbor_offsets_, neighbors_;
  std::vector<double> neighbor_length_;
  double mean_edge_length_ = 0, max_edge_length_ = 0;
  MeshReport report_;
  std::shared_ptr<ich::WorkspaceCache> workspaces_;
};

}  // namespace geodex
