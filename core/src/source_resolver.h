#pragma once

// Resolves user-facing SurfacePoints (file ids, file corner order) into the engine's internal
// placements: vertex copies, or points in faces in the frame of half-edge 3*face. Private to core.

#include <array>
#include <cmath>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "dijkstra.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "ich/ich_solver.h"
#include "mesh_lookup.h"

namespace geodex {

class SourceResolver {
 public:
  explicit SourceResolver(const TriangleMesh& mesh) : mesh_(mesh) {}

  absl::Status Add(const SurfacePoint& p, uint32_t label) {
    if (absl::Status s = ValidateSurfacePoint(mesh_, p); !s.ok()) return s;
    // Errors name the point as given; it is placed as its canonical form (surface_point.h).
    const SurfacePoint c = CanonicalPoint(mesh_, p);
    switch (c.kind) {
      case SurfacePoint::Kind::kVertex:
        return AddVertex(c.vertex, label);
      case SurfacePoint::Kind::kEdge:
        return AddEdgePoint(p, c.edge_from, c.edge_to, c.t, label);
      case SurfacePoint::Kind::kFace:
        return AddFacePoint(p, c, label);
      case SurfacePoint::Kind::kPosition:
        break;  // rejected by ValidateSurfacePoint above
    }
    return absl::OkStatus();
  }

  const std::vector<ich::ResolvedSource>& sources() const { return sources_; }

 private:
  absl::Status AddVertex(uint32_t file_vertex, uint32_t label) {
    InternalCopies(mesh_, file_vertex, &copies_);
    for (uint32_t v : copies_) {
      ich::ResolvedSource s;
      s.is_vertex = true;
      s.vertex = v;
      s.label = label;
      sources_.push_back(s);
    }
    return absl::OkStatus();
  }

  absl::Status AddEdgePoint(const SurfacePoint& p, uint32_t a, uint32_t b, double t,
                            uint32_t label) {
    HalfEdgesOfFileEdge(mesh_, a, b, &half_edges_);
    const bool found = !half_edges_.empty();
    bool placed = false;
    for (const uint32_t h : half_edges_) {
      const bool forward = mesh_.FileVertex(mesh_.From(h)) == a;
      const uint32_t f = TriangleMesh::FaceOf(h);
      if (mesh_.FaceDegenerate(f)) continue;
      const double len = mesh_.Length(h);
      const double x = (forward ? t : 1 - t) * len;
      const int k = static_cast<int>(h % 3);
      double x0, y0, x1, y1;
      CornerInFaceFrame(mesh_, f, k, &x0, &y0);
      CornerInFaceFrame(mesh_, f, (k + 1) % 3, &x1, &y1);
      PlaceInFace(f, x0 + (x1 - x0) * x / len, y0 + (y1 - y0) * x / len, label);
      placed = true;
    }
    if (!found) {
      return absl::InvalidArgumentError(
          absl::StrFormat("point %s: the mesh has no edge between vertices %d and %d",
                          SurfacePointToString(p), a, b));
    }
    if (!placed) {
      return absl::InvalidArgumentError(
          absl::StrFormat("point %s: the edge %d-%d belongs only to degenerate (zero-area) faces",
                          SurfacePointToString(p), a, b));
    }
    return absl::OkStatus();
  }

  // `c` is the canonical face point (normalised barycentrics, in the file's corner order).
  absl::Status AddFacePoint(const SurfacePoint& p, const SurfacePoint& c, uint32_t label) {
    const uint32_t f = c.face;
    if (mesh_.FaceDegenerate(f)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "point %s: face %d is degenerate (zero area)", SurfacePointToString(p), f));
    }
    std::array<double, 3> ib = c.bary;
    mesh_.SwapCornerOrder(f, &ib);  // internal barycentrics follow the internal corner order
    double x1, y1, x2, y2;
    CornerInFaceFrame(mesh_, f, 1, &x1, &y1);
    CornerInFaceFrame(mesh_, f, 2, &x2, &y2);
    PlaceInFace(f, ib[1] * x1 + ib[2] * x2, ib[1] * y1 + ib[2] * y2, label);
    return absl::OkStatus();
  }

  void PlaceInFace(uint32_t f, double px, double py, uint32_t label) {
    ich::ResolvedSource s;
    s.is_vertex = false;
    s.face = f;
    s.px = px;
    s.py = py;
    s.label = label;
    sources_.push_back(s);
  }

  const TriangleMesh& mesh_;
  std::vector<ich::ResolvedSource> sources_;
  std::vector<uint32_t> copies_;
  std::vector<uint32_t> half_edges_;
};

inline std::vector<VertexSeed> SeedsForDijkstra(const TriangleMesh& mesh,
                                                const std::vector<ich::ResolvedSource>& sources) {
  std::vector<VertexSeed> seeds;
  for (const ich::ResolvedSource& s : sources) {
    if (s.is_vertex) {
      seeds.push_back({s.vertex, 0.0, s.label});
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      double x, y;
      CornerInFaceFrame(mesh, s.face, k, &x, &y);
      seeds.push_back({mesh.FaceVertex(s.face, k), std::hypot(s.px - x, s.py - y), s.label});
    }
  }
  return seeds;
}

}  // namespace geodex
