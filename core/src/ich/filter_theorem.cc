// Lemma 2, the filter theorem (Xin & Wang 2009): a window is dropped, or trimmed, where
// every point of its interval is reached more cheaply straight from a vertex of the faces around
// it.

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {

bool IchSolver::IsFiltered(uint32_t he, double b0, double b1, double ix, double iy, double sigma,
                           double ra, double rb, WindowSide side, double epsilon) const {
  const double len = mesh_.Length(he);
  const double d_a = sigma + ra;  // through the window at interval end A (b0)
  const double d_b = sigma + rb;  // at interval end B (b1)
  const uint32_t v_start = mesh_.From(he), v_end = mesh_.To(he);
  // Each edge endpoint is paired with the interval end FARTHER from it: along the edge,
  // sigma + |I p| - |v p| is monotone, so that end bounds the whole interval (docs/numerics.md).
  const double r1 = dist_[v_start] + b1;
  const double r2 = dist_[v_end] + (len - b0);
  if (epsilon > 0) {
    // Section 7's over-filtering (>=, with the margin): lambda = 1 filters every interval window.
    if (d_b + epsilon >= r1 * (1 - kFilterRelTol)) return true;
    if (d_a + epsilon >= r2 * (1 - kFilterRelTol)) return true;
  } else {
    if (d_b > r1 + kFilterRelTol * d_b) return true;
    if (d_a > r2 + kFilterRelTol * d_a) return true;
  }
  // The vertex ahead (opposite this half-edge): if every point of the interval is reached more
  // cheaply straight from it, the window is useless beyond the edge. |I p| - |v p| along the edge
  // has a single critical point, where the line through I and v's mirror image meets the edge, so
  // its minimum over the interval is at an end or there.
  {
    const double x3 = mesh_.OppX(he), y3 = mesh_.OppY(he);
    const double d3 = dist_[mesh_.Opposite(he)];
    auto excess = [&](double p) {
      return sigma + Hypot(p - ix, iy) - Hypot(p - x3, y3);  // compared against d3
    };
    double lowest = std::min(d_a - Hypot(b0 - x3, y3), d_b - Hypot(b1 - x3, y3));
    const double denom = iy + y3;
    if (denom != 0) {
      const double p0 = ix + (x3 - ix) * iy / denom;
      if (p0 > b0 && p0 < b1) lowest = std::min(lowest, excess(p0));
    }
    if (lowest > d3 + kFilterRelTol * (d3 + len)) return true;
  }
  if (side == WindowSide::kInitial) return false;  // third vertex = the pseudo-source itself
  // The third vertex of the face the window came through (opposite the twin), paired with the
  // interval end nearer the vertex this edge shares with the parent's edge: the start for a left
  // child, the end for a right child. Rays through the parent's edge make
  // sigma + |I p| - |v3 p| non-decreasing away from that shared vertex.
  const uint32_t tw = mesh_.Twin(he);
  const double tx = len - mesh_.OppX(tw), ty = -mesh_.OppY(tw);
  const double d_third = dist_[mesh_.Opposite(tw)];
  if (side == WindowSide::kLeft) {
    const double r3 = d_third + Hypot(b0 - tx, ty);
    return d_a > r3 + kFilterRelTol * d_a;
  }
  const double r3 = d_third + Hypot(b1 - tx, ty);
  return d_b > r3 + kFilterRelTol * d_b;
}

bool IchSolver::TrimByEndpoints(uint32_t he, double* b0, double* b1, double ix, double iy,
                                double sigma, double* ra, double* rb) const {
  // The filter theorem applied point by point: along the edge, sigma + |I p| - |v p| is monotone
  // for either endpoint v, so the points better reached straight from v form a prefix (start
  // vertex) or a suffix (end vertex) of the interval; cut them off. Returns false when nothing is
  // left.
  // On the way out, *ra and *rb are |I b0| and |I b1| for the (trimmed) interval.
  const double len = mesh_.Length(he);
  const double iy2 = iy * iy;
  auto r = [&](double p) { return std::sqrt((p - ix) * (p - ix) + iy2); };
  double r0 = r(*b0), r1 = r(*b1);
  {
    const double d = dist_[mesh_.From(he)];
    const double thr = d + kFilterRelTol * (d + len);
    // g(p) = sigma + |I p| - p
    if (sigma + r1 - *b1 > thr) return false;
    if (sigma + r0 - *b0 > thr) {
      // Solve sigma + |I p| = thr + p for p.
      const double s = thr - sigma;
      const double p = (ix * ix + iy2 - s * s) / (2 * (ix + s));
      if (p > *b0 && p <= *b1) {
        *b0 = p;
        r0 = r(p);
      }
    }
  }
  {
    const double d = dist_[mesh_.To(he)];
    const double thr = d + kFilterRelTol * (d + len);
    // g(p) = sigma + |I p| - (len - p)
    if (sigma + r0 - (len - *b0) > thr) return false;
    if (sigma + r1 - (len - *b1) > thr) {
      // Mirror of the case above, measured from the end vertex.
      const double s = thr - sigma, mx = len - ix;
      const double q = (mx * mx + iy2 - s * s) / (2 * (mx + s));
      const double p = len - q;
      if (p >= *b0 && p < *b1) {
        *b1 = p;
        r1 = r(p);
      }
    }
  }
  *ra = r0;
  *rb = r1;
  return *b1 - *b0 > kTinyWindowRel * len;
}

}  // namespace geodex::ich
