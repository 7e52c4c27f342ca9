// Target bookkeeping: the points a targeted solve must answer exactly (paths, matrices, exact
// point distances) are offered every window and vertex that can reach them straight.

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {

void IchSolver::Offer(uint32_t t, uint32_t placement, double d, uint32_t label,
                      const VertexOrigin& origin, double tx, double ty) {
  TargetResult& r = (*target_results_)[t];
  if (!(d < r.distance)) return;
  const ResolvedTarget& target = (*targets_)[t];
  r.distance = d;
  r.label = label;
  r.origin = origin;
  r.tx = tx;
  r.ty = ty;
  r.face = target.placements[placement].face;
  r.px = target.placements[placement].px;
  r.py = target.placements[placement].py;
  targets_dirty_ = true;
}

void IchSolver::OfferWindowToTargets(uint32_t h, const Window& w) {
  const uint32_t f = TriangleMesh::FaceOf(h);
  const int k = static_cast<int>(h % 3), k1 = (k + 1) % 3;
  const double cx[3] = {0, mesh_.Length(3 * f), mesh_.OppX(3 * f)};
  const double cy[3] = {0, 0, mesh_.OppY(3 * f)};
  const double len = mesh_.Length(h);
  const double ux = (cx[k1] - cx[k]) / len, uy = (cy[k1] - cy[k]) / len;
  for (uint32_t e = face_target_head_[f]; e != kNoIndex; e = face_target_next_[e]) {
    const auto [t, placement] = face_target_entry_[e];
    const ResolvedTarget::Placement& at = (*targets_)[t].placements[placement];
    // The target in h's frame (+y into the face).
    const double qx = (at.px - cx[k]) * ux + (at.py - cy[k]) * uy;
    const double qy = -(at.px - cx[k]) * uy + (at.py - cy[k]) * ux;
    // Reached through this window when the segment image -> target crosses the interval.
    const double cross = qy - w.iy > 0 ? w.ix + (qx - w.ix) * (-w.iy) / (qy - w.iy) : qx;
    const double tol = kCoverRelTol * len;
    if (cross < w.b0 - tol || cross > w.b1 + tol) continue;
    const uint32_t ps = w.pseudo_source;
    Offer(t, placement, w.sigma + Hypot(qx - w.ix, qy - w.iy), w.source,
          VertexOrigin{h, ps, w.ix, w.iy}, qx, qy);
  }
}

void IchSolver::OfferPointToTargets(uint32_t f, double px, double py, double d, uint32_t label,
                                    uint32_t via_vertex, uint32_t frame_edge, double fx,
                                    double fy) {
  // px, py: the point in the frame of half-edge 3f. A vertex is an origin of its own; a source
  // point is given as an image in the frame of `frame_edge` (inside the face).
  for (uint32_t e = face_target_head_[f]; e != kNoIndex; e = face_target_next_[e]) {
    const auto [t, placement] = face_target_entry_[e];
    const ResolvedTarget::Placement& at = (*targets_)[t].placements[placement];
    const double dd = d + Hypot(at.px - px, at.py - py);
    if (via_vertex != kNoIndex && !IsBoundaryPoint(via_vertex)) {
      Offer(t, placement, dd, label, VertexOrigin{kNoIndex, via_vertex, 0, 0}, 0, 0);
    } else {
      Offer(t, placement, dd, label, VertexOrigin{frame_edge, kNoIndex, fx, fy}, at.px, at.py);
    }
  }
}

double IchSolver::CurrentTargetDistance(uint32_t t) const {
  double d = (*target_results_)[t].distance;
  for (uint32_t v : (*targets_)[t].vertices) d = std::min(d, dist_[v]);
  return d;
}

double IchSolver::TargetsBound() {
  if (!targets_dirty_) return targets_bound_;
  targets_dirty_ = false;
  const size_t n = targets_->size();
  double bound = 0;
  if (final_needed_ == 0 || final_needed_ >= n) {
    for (uint32_t t = 0; t < n; ++t) bound = std::max(bound, CurrentTargetDistance(t));
  } else {
    // Once the queue's floor passes the k-th smallest upper bound, at least k targets are final,
    // and every target not among them is at least the floor away: those k are the k nearest.
    bound_scratch_.clear();
    for (uint32_t t = 0; t < n; ++t) bound_scratch_.push_back(CurrentTargetDistance(t));
    std::nth_element(bound_scratch_.begin(), bound_scratch_.begin() + (final_needed_ - 1),
                     bound_scratch_.end());
    bound = bound_scratch_[final_needed_ - 1];
  }
  if (refit_goal_) {
    next_final_ = kUnreachable;
    for (uint32_t t : unfinished_) next_final_ = std::min(next_final_, CurrentTargetDistance(t));
  }
  targets_bound_ = bound;
  return bound;
}

}  // namespace geodex::ich
