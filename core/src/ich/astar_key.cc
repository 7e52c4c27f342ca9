// The A* key of section 5: a window's key is a lower bound of the length of any path through it
// to the target, so the search stops once the target is final. With several targets (a matrix
// row, distances at points) the target is a ball (centre c, radius r) holding them all: for any
// target t, |p t| >= |p c| - r, so the single-target key towards c, less r, still bounds every
// path through the window to any of them, and never decreases along a path (as the paper's).
// As the row's near targets become final the ball is fitted again around the rest, so the search
// narrows towards the far ones instead of growing a disk out to them.

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {
namespace {
// Several targets get the A* key only when their ball's radius is at most this fraction of the
// mesh's bounding-box diagonal (waypoints of a local plan, not points spread over the mesh).
constexpr double kGoalBallMaxRel = 0.25;
}  // namespace

double IchSolver::WindowKey(uint32_t h, double b0, double b1, double ix, double iy, double sigma,
                            double plain_key) const {
  // Section 5: rotate the target about this edge's line into the window's plane, on the far side
  // (distances from points of the edge are unchanged), then min over p of |I p| + |p t'| is the
  // straight segment I t' if it crosses the interval, else the better interval end. Exact, so the
  // key is a true lower bound of any path through the window.
  const double* pos = mesh_.positions();
  const double* a = pos + 3 * mesh_.From(h);
  const double* b = pos + 3 * mesh_.To(h);
  const double* t = goal_;
  const double len = mesh_.Length(h);
  const double d[3] = {t[0] - a[0], t[1] - a[1], t[2] - a[2]};
  const double tx = (d[0] * (b[0] - a[0]) + d[1] * (b[1] - a[1]) + d[2] * (b[2] - a[2])) / len;
  const double ty = std::sqrt(std::max(0.0, d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - tx * tx));
  const double cross = ix + (tx - ix) * (-iy) / (ty - iy);
  double best;
  if (cross >= b0 && cross <= b1) {
    best = Hypot(tx - ix, ty - iy);
  } else {
    best =
        std::min(Hypot(b0 - ix, iy) + Hypot(tx - b0, ty), Hypot(b1 - ix, iy) + Hypot(tx - b1, ty));
  }
  return std::max(plain_key, sigma + best - goal_radius_);
}

double IchSolver::VertexKey(uint32_t v, double d) const {
  if (!heuristic_) return d;
  const double* p = mesh_.positions() + 3 * v;
  const double* t = goal_;
  return d + std::max(0.0, std::sqrt((p[0] - t[0]) * (p[0] - t[0]) + (p[1] - t[1]) * (p[1] - t[1]) +
                                     (p[2] - t[2]) * (p[2] - t[2])) -
                               goal_radius_);
}

bool IchSolver::FitGoal() {
  if (unfinished_.empty()) return false;
  const std::vector<ResolvedTarget>& targets = *targets_;
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = targets[unfinished_[0]].position[k];
  for (uint32_t t : unfinished_) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], targets[t].position[k]);
      hi[k] = std::max(hi[k], targets[t].position[k]);
    }
  }
  for (int k = 0; k < 3; ++k) goal_[k] = 0.5 * (lo[k] + hi[k]);
  double r2 = 0;
  for (uint32_t t : unfinished_) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      d2 += (targets[t].position[k] - goal_[k]) * (targets[t].position[k] - goal_[k]);
    }
    r2 = std::max(r2, d2);
  }
  // Round the radius up: the bound must hold for every target despite round-off.
  goal_radius_ = unfinished_.size() == 1 ? 0 : std::sqrt(r2) * (1 + 1e-12);
  // A ball reaching over much of the mesh steers nothing and costs a key per window.
  double diagonal2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double e = mesh_.BoundsMax()[k] - mesh_.BoundsMin()[k];
    diagonal2 += e * e;
  }
  return unfinished_.size() == 1 || goal_radius_ <= kGoalBallMaxRel * std::sqrt(diagonal2);
}

void IchSolver::RefitGoal(double floor) {
  // Keys already queued were made with a ball holding every target still unfinished, so they
  // stay lower bounds for those. A key made with the smaller ball may fall below its parent's:
  // the queue lifts it to its floor, still a bound (every path through a child runs through its
  // parent, whose key bounds them all).
  size_t kept = 0;
  for (uint32_t t : unfinished_) {
    if (CurrentTargetDistance(t) > floor) unfinished_[kept++] = t;
  }
  unfinished_.resize(kept);
  // Once on, the A* key stays on: a ball too large to pay for itself is still a valid bound.
  if (FitGoal()) heuristic_ = true;
  targets_dirty_ = true;  // next_final_ among the rest
}

}  // namespace geodex::ich
