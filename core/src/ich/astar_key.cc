// The A* key of section 5 (single-target queries): a window's key is a lower bound of the
// length of any path through it to the target, so the search stops once the target is final.

#include "ich/ich_solver.h"

#include <algorithm>
#include <cmath>

#include "ich/numerics.h"

namespace geodex::ich {

double IchSolver::WindowKey(uint32_t h, double b0, double b1, double ix, double iy, double sigma,
                           double plain_key) const {
  // Section 5: rotate the target about this edge's line into the window's plane, on the far side
  // (distances from points of the edge are unchanged), then min over p of |I p| + |p t'| is the
  // straight segment I t' if it crosses the interval, else the better interval end. Exact, so the
  // key is a true lower bound of any path through the window.
  const double* pos = mesh_.positions();
  const double* a = pos + 3 * mesh_.From(h);
  const double* b = pos + 3 * mesh_.To(h);
  const double* t = (*targets_)[0].position;
  const double len = mesh_.Length(h);
  const double d[3] = {t[0] - a[0], t[1] - a[1], t[2] - a[2]};
  const double tx = (d[0] * (b[0] - a[0]) + d[1] * (b[1] - a[1]) + d[2] * (b[2] - a[2])) / len;
  const double ty = std::sqrt(std::max(0.0, d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - tx * tx));
  const double cross = ix + (tx - ix) * (-iy) / (ty - iy);
  double best;
  if (cross >= b0 && cross <= b1) {
    best = Hypot(tx - ix, ty - iy);
  } else {
    best = std::min(Hypot(b0 - ix, iy) + Hypot(tx - b0, ty), Hypot(b1 - ix, iy) + Hypot(tx - b1, ty));
  }
  return std::max(plain_key, sigma + best);
}

double IchSolver::VertexKey(uint32_t v, double d) const {
  if (!heuristic_) return d;
  const double* p = mesh_.positions() + 3 * v;
  const double* t = (*targets_)[0].position;
  return d + std::sqrt((p[0] - t[0]) * (p[0] - t[0]) + (p[1] - t[1]) * (p[1] - t[1]) +
                       (p[2] - t[2]) * (p[2] - t[2]));
}

}  // namespace geodex::ich
