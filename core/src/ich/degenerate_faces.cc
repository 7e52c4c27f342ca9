// Zero-area faces: a window or a vertex passes through a face collapsed to a segment.

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {

void IchSolver::EmitAcrossDegenerate(uint32_t id, uint32_t corner, double sigma, uint32_t source) {
  // v sits on the segment a zero-area face collapses to; the face across that face's opposite
  // edge sees v as a point on its own edge, so paths leave v into it as from a point source.
  const uint32_t v = mesh_.From(corner);
  const uint32_t t = mesh_.Twin(TriangleMesh::Next(corner));
  if (t == kNoIndex || mesh_.FaceDegenerate(TriangleMesh::FaceOf(t))) return;
  const double len = mesh_.Length(t);
  if (!(len > 0)) return;
  const double* pos = mesh_.positions();
  const double* a = pos + 3 * mesh_.From(t);
  const double* b = pos + 3 * mesh_.To(t);
  const double* p = pos + 3 * v;
  const double x = ((p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1]) +
                    (p[2] - a[2]) * (b[2] - a[2])) /
                   len;
  if (!(x > 0 && x < len)) return;  // v is an end of that edge: its own fan covers it
  EmitFromPointInFace(id, t, x, 0, sigma, v, source);
}

void IchSolver::PassThroughDegenerate(uint32_t id, const Window& w) {
  // A zero-area face is a segment: the window's points on edge h lie on the face's other edges
  // too, and paths continue straight into the faces beyond them. Positions are measured along
  // h's line in 3D; the image keeps its distance from the line, behind the next edge.
  const uint32_t h = w.element;
  const double len = mesh_.Length(h);
  if (!(len > 0)) return;
  const double* pos = mesh_.positions();
  const double* a = pos + 3 * mesh_.From(h);
  const double* b = pos + 3 * mesh_.To(h);
  const double u[3] = {(b[0] - a[0]) / len, (b[1] - a[1]) / len, (b[2] - a[2]) / len};
  auto along = [&](uint32_t v) {
    const double* p = pos + 3 * v;
    return (p[0] - a[0]) * u[0] + (p[1] - a[1]) * u[1] + (p[2] - a[2]) * u[2];
  };
  // The face's middle vertex, if the window covers it, is reached straight.
  const uint32_t v3 = mesh_.Opposite(h);
  const double s3 = along(v3);
  if (s3 >= w.b0 && s3 <= w.b1)
    UpdateVertex(v3, w.sigma + Hypot(s3 - w.ix, w.iy), id, h, w.ix, w.iy);
  const uint32_t others[2] = {TriangleMesh::Next(h), TriangleMesh::Prev(h)};
  for (const uint32_t e : others) {
    const uint32_t t = mesh_.Twin(e);
    if (t == kNoIndex) continue;
    const double s_origin = along(mesh_.From(t)), s_end = along(mesh_.To(t));
    const double dir = s_end >= s_origin ? 1.0 : -1.0;
    const double o0 = std::max(w.b0, std::min(s_origin, s_end));
    const double o1 = std::min(w.b1, std::max(s_origin, s_end));
    if (!(o1 > o0)) continue;
    const double tl = mesh_.Length(t);
    double x0 = (o0 - s_origin) * dir, x1 = (o1 - s_origin) * dir;
    if (x0 > x1) std::swap(x0, x1);
    x0 = std::max(0.0, x0);
    x1 = std::min(tl, x1);
    MakeInterval(id, t, x0, x1, (w.ix - s_origin) * dir, -std::abs(w.iy), WindowSide::kInitial,
                 w.pseudo_source, w.sigma, w.source);
  }
}

}  // namespace geodex::ich
