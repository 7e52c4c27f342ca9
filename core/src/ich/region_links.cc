// Where the regions of a weighted surface meet (region_links.h): boundary points and vertex
// copies. Inside a region the engine's own rules apply unchanged (lengths there are costs).

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {

void IchSolver::ReachBoundary(uint32_t e, double x0, double x1, double ix, double iy, double sigma,
                              uint32_t source, uint32_t pseudo_source) {
  const uint32_t c = regions_->chain_of_half[e];
  if (c == kNoIndex) return;  // a true boundary, or an impassable face beyond
  const double len = mesh_.Length(e);
  if (iy > -kGrazingRel * len) return;  // rays along the edge: the chain's own links carry them
  if (sigma - iy > key_cap_) return;
  // Positions are measured from e's end; a point at parameter t along the chain lies at
  // len x (1 - t) from it, or len x t when the chain runs from e's end.
  const bool reversed = regions_->chain_reversed[e];
  const double tol = kCoverRelTol * len;
  const double lo = (x0 - tol) / len, hi = (x1 + tol) / len;
  const double t_lo = reversed ? lo : 1 - hi, t_hi = reversed ? hi : 1 - lo;
  const double* param = regions_->point_param.data();
  const double* begin = param + regions_->chain_first[c];
  const double* end = param + regions_->chain_first[c + 1];
  auto i = static_cast<uint32_t>(std::lower_bound(begin, end, t_lo) - param);
  const auto stop = static_cast<uint32_t>(std::upper_bound(param + i, end, t_hi) - param);
  auto x_of = [&](uint32_t p) { return len * (reversed ? param[p] : 1 - param[p]); };
  // Where each point reached here took its cost from: this window, its image in e's own frame
  // (the twin's (ix, iy) mirrored).
  const VertexOrigin origin{e, pseudo_source, len - ix, -iy};
  while (i < stop) {
    const uint32_t b = i / kPointBlock;
    const uint32_t run_end = std::min(stop, (b + 1) * kPointBlock);
    // The window's least cost over the run's stretch [lo, hi] of the edge (rounding is monotone,
    // so no point of the run costs less than this as ReachPoint would compute it).
    const double xa = x_of(i), xb = x_of(run_end - 1);
    const double lo = std::min(xa, xb), hi = std::max(xa, xb);
    const double dx = ix < lo ? lo - ix : (ix > hi ? ix - hi : 0.0);
    if (sigma + Hypot(dx, iy) >= block_max_[b]) {
      i = run_end;
      continue;
    }
    for (; i < run_end; ++i) ReachPoint(i, sigma + Hypot(x_of(i) - ix, iy), source, origin);
  }
}

void IchSolver::ReachPoint(uint32_t p, double d, uint32_t source, const VertexOrigin& origin) {
  if (!(d < point_cost_[p]) || d > key_cap_) return;
  const double old = point_cost_[p];
  point_cost_[p] = d;
  // Keep the run's largest cost: it can only have dropped if p held it.
  double& run_max = block_max_[p / kPointBlock];
  if (old == run_max) {
    const uint32_t first = p / kPointBlock * kPointBlock;
    const uint32_t last =
        std::min<uint32_t>(first + kPointBlock, static_cast<uint32_t>(point_cost_.size()));
    run_max = *std::max_element(point_cost_.begin() + first, point_cost_.begin() + last);
  }
  point_origin_[p] = origin;
  point_source_[p] = source;
  // Its queued entry, if it pops in this slot anyway, serves: the point is processed at the cost
  // it has then.
  const uint64_t slot = queue_.SlotOf(d);
  if (point_slot_[p] == slot) return;
  point_slot_[p] = slot;
  ++stats_.pseudo_sources;
  queue_.Push({d, kPointEntry | p, ++point_seq_[p]});
}

void IchSolver::ProcessBoundaryPoint(uint32_t p) {
  point_slot_[p] = kNoSlot;
  // Its window exists only while it emits (the parent of what it makes).
  const uint32_t id = NewPointWindow(WindowKind::kBoundaryPoint, p, kBoundaryPointTag | p,
                                     point_cost_[p], point_source_[p], 0);
  const Window w = pool_[id];
  pool_.MarkProcessed(id);
  const uint32_t c = regions_->point_chain[p];
  const double t = regions_->point_param[p];
  const uint32_t first = regions_->chain_first[c], end = regions_->chain_first[c + 1];
  // Into both regions as a point source on their edge; the side whose window set the cost needs
  // nothing more from it (straight on from that window's image is never longer). Nor does a side
  // where a neighbour on the chain plus the way along the edge at that side's cost is no dearer
  // than p: by the triangle inequality in that region, what p would reach there the neighbour
  // reaches for no more (it emitted, or is covered the same way). The way's cost is the side's
  // cost per unit of parameter x the step, computed as a cost passed along the chain is (on the
  // lighter side the two agree bit for bit, so a point priced by its neighbour is covered).
  auto covered_by_neighbour = [&](double side_cost) {
    for (const uint32_t k : {p - 1, p + 1}) {
      if (k < first || k >= end) continue;  // (p - 1 wraps at 0: above end)
      // (strictly cheaper, so two points a rounding apart cannot each leave the side to the other)
      if (point_cost_[k] < w.sigma &&
          point_cost_[k] + side_cost * std::abs(t - regions_->point_param[k]) <= w.sigma) {
        return true;
      }
    }
    return false;
  };
  for (int side = 0; side < 2; ++side) {
    const uint32_t e = regions_->chain_halves[c][side];
    if (e == kNoIndex || e == point_origin_[p].half_edge) continue;
    if (covered_by_neighbour(regions_->side_cost[c][side])) continue;
    const double len = mesh_.Length(e);
    EmitFromPointInFace(id, e, len * (regions_->chain_reversed[e] ? 1 - t : t), 0, w.sigma,
                        kBoundaryPointTag | p, w.source);
  }
  // Along the edge, to its neighbours (the ends are the edge's vertices, reached straight above).
  const double cost = regions_->chain_cost[c];
  if (p > first) {
    ReachPoint(p - 1, w.sigma + cost * (t - regions_->point_param[p - 1]), w.source,
               VertexOrigin{kNoIndex, kBoundaryPointTag | p, 0, 0});
  }
  if (p + 1 < end) {
    ReachPoint(p + 1, w.sigma + cost * (regions_->point_param[p + 1] - t), w.source,
               VertexOrigin{kNoIndex, kBoundaryPointTag | p, 0, 0});
  }
  ReleaseIfDone(id);
}

void IchSolver::ShareWithCopies(uint32_t v, double d, uint32_t source) {
  for (uint32_t u = regions_->next_copy[v]; u != v; u = regions_->next_copy[u]) {
    if (!(d < dist_[u])) continue;
    SetVertex(u, d, source, VertexOrigin{kNoIndex, v, 0, 0});
    if (d > options_.max_distance) continue;
    // A copy lies on its region's boundary: a pseudo-source, its windows all around.
    const uint32_t id = NewPseudoSourceWindow(u, d, source, 0);
    ++stats_.pseudo_sources;
    Push(id, d);
  }
}

void IchSolver::RelaxChainEnds(uint32_t v, double d, uint32_t source) {
  for (const uint32_t* corner = mesh_.CornersBegin(v); corner != mesh_.CornersEnd(v); ++corner) {
    // The face's two edges at v: the one leaving v and the one arriving.
    for (const uint32_t e : {*corner, TriangleMesh::Prev(*corner)}) {
      const uint32_t c = regions_->chain_of_half[e];
      if (c == kNoIndex) continue;
      const uint32_t first = regions_->chain_first[c], last = regions_->chain_first[c + 1];
      if (first == last) continue;
      // The chain's start is e's start unless reversed; v is e's start when e leaves v.
      const bool v_at_chain_start = (e == *corner) != (regions_->chain_reversed[e] != 0);
      const uint32_t p = v_at_chain_start ? first : last - 1;
      const double t = regions_->point_param[p];
      ReachPoint(p, d + regions_->chain_cost[c] * (v_at_chain_start ? t : 1 - t), source,
                 VertexOrigin{kNoIndex, v, 0, 0});
    }
  }
}

}  // namespace geodex::ich
