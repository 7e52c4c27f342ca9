// Lemma 1, one angle one split (Chen & Han): of the windows on a directed edge that see its
// opposite vertex, only the one giving that vertex the smallest distance keeps both children.

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {

bool IchSolver::OneAngleOneSplit(uint32_t id, uint32_t generation, uint32_t h, double d3,
                                 double cross_x, double cover_tol, bool* make_left,
                                 bool* make_right) {
  // Lemma 1 (one angle one split): of the windows on this directed edge that see v3, only the
  // one giving v3 the smallest distance keeps both children; a loser keeps the child on the
  // side where its own ray to v3 crosses the edge relative to the winner's.
  SplitRecord& best = split_[h];
  const double tie = kSplitTieRel * d3;
  if (d3 < best.distance - tie) {
    if (keep_tree()) {
      // The paper's retroactive rule: the old winner's child on the far side is useless.
      const SplitOwner& owner = split_owner_[h];
      if (owner.window != kNoIndex && pool_.links(owner.window).generation == owner.generation &&
          pool_.links(owner.window).state != WindowState::kFree) {
        const bool old_is_right = best.cross_x > cross_x + cover_tol;
        const bool old_is_left = best.cross_x < cross_x - cover_tol;
        if (old_is_right || old_is_left) {
          const WindowSide doomed = old_is_right ? WindowSide::kLeft : WindowSide::kRight;
          for (uint32_t c = pool_.links(owner.window).first_child; c != kNoIndex;) {
            const uint32_t next = pool_.links(c).next_sibling;
            if (pool_.links(c).kind == WindowKind::kInterval && pool_.links(c).side == doomed) {
              DeleteSubtree(c);
              break;
            }
            c = next;
          }
        }
      }
      // A pathological unfolding may revisit this edge inside the deleted subtree.
      if (pool_.links(id).state != WindowState::kProcessed ||
          pool_.links(id).generation != generation) {
        return false;
      }
      split_owner_[h] = SplitOwner{id, generation};
    }
    if (best.distance == kUnreachable) workspace_->touched_half_edges.push_back(h);
    best.distance = d3;
    best.cross_x = cross_x;
  } else if (d3 > best.distance + tie) {
    if (cross_x > best.cross_x + cover_tol) {
      if (*make_left) ++stats_.children_skipped_one_split;
      *make_left = false;
    } else if (cross_x < best.cross_x - cover_tol) {
      if (*make_right) ++stats_.children_skipped_one_split;
      *make_right = false;
    }
  }
  return true;
}

}  // namespace geodex::ich
