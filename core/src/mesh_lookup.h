#pragma once

// Small lookups shared by the code that places surface points on faces (private to core).

#include <cmath>
#include <cstdint>
#include <vector>

#include "geodex/triangle_mesh.h"

namespace geodex {

// Corner k of face f in the frame of half-edge 3f (corner 0 at the origin, corner 1 on +x).
inline void CornerInFaceFrame(const TriangleMesh& mesh, uint32_t f, int k, double* x, double* y) {
  if (k == 0) {
    *x = 0, *y = 0;
  } else if (k == 1) {
    *x = mesh.Length(3 * f), *y = 0;
  } else {
    *x = mesh.OppX(3 * f), *y = mesh.OppY(3 * f);
  }
}

// The internal vertices of a file vertex: itself, then its copies at non-manifold junctions.
inline void InternalCopies(const TriangleMesh& mesh, uint32_t file_vertex,
                           std::vector<uint32_t>* out) {
  out->clear();
  out->push_back(file_vertex);
  const std::vector<uint32_t>& copies = mesh.copy_of();
  for (uint32_t i = 0; i < copies.size(); ++i) {
    if (copies[i] == file_vertex) out->push_back(mesh.file_vertex_count() + i);
  }
}

// Every half-edge whose file endpoints are {a, b}, in either direction (one per face on the edge).
inline void HalfEdgesOfFileEdge(const TriangleMesh& mesh, uint32_t a, uint32_t b,
                                std::vector<uint32_t>* out) {
  out->clear();
  std::vector<uint32_t> copies;
  InternalCopies(mesh, a, &copies);
  for (uint32_t va : copies) {
    for (const uint32_t* c = mesh.CornersBegin(va); c != mesh.CornersEnd(va); ++c) {
      // Corner c starts half-edge c (a -> next); half-edge Prev(c) ends at a.
      for (const uint32_t h : {*c, TriangleMesh::Prev(*c)}) {
        const uint32_t from = mesh.FileVertex(mesh.From(h)), to = mesh.FileVertex(mesh.To(h));
        if ((from == a && to == b) || (from == b && to == a)) out->push_back(h);
      }
    }
  }
}

}  // namespace geodex

namespace geodex {

// The internal (recentred) 3D position of the point (px, py) given in the frame of half-edge 3f.
inline void FacePointPosition(const TriangleMesh& mesh, uint32_t f, double px, double py,
                              double out[3]) {
  const double* pos = mesh.positions();
  const double* a = pos + 3 * mesh.FaceVertex(f, 0);
  const double* b = pos + 3 * mesh.FaceVertex(f, 1);
  const double* c = pos + 3 * mesh.FaceVertex(f, 2);
  const double len = mesh.Length(3 * f);
  double u[3], w[3], dot = 0, norm = 0;
  for (int k = 0; k < 3; ++k) u[k] = len > 0 ? (b[k] - a[k]) / len : 0;
  for (int k = 0; k < 3; ++k) dot += (c[k] - a[k]) * u[k];
  for (int k = 0; k < 3; ++k) {
    w[k] = c[k] - a[k] - dot * u[k];
    norm += w[k] * w[k];
  }
  norm = std::sqrt(norm);
  for (int k = 0; k < 3; ++k) out[k] = a[k] + px * u[k] + py * (norm > 0 ? w[k] / norm : 0);
}

}  // namespace geodex
