// The paper's window tree (Method::kIch only): children linked to parents so Lemma 1 can delete
// an old winner's subtree; without it (Method::kExact) a window is freed once processed.

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {

void IchSolver::ReleaseIfDone(uint32_t id) {
  if (!keep_tree()) {  // no tree: nothing can refer to a processed window
    pool_.Free(id);
    return;
  }
  // Frees processed windows that have no children left, walking up: the tree keeps only what
  // Lemma 1 may still need to prune.
  while (id != kNoIndex) {
    const WindowLinks& w = pool_.links(id);
    if (w.state != WindowState::kProcessed || w.first_child != kNoIndex) return;
    const uint32_t parent = w.parent;
    pool_.Unlink(id);
    pool_.Free(id);
    id = parent;
  }
}

void IchSolver::DeleteSubtree(uint32_t root) {
  const uint32_t parent = pool_.links(root).parent;
  pool_.Unlink(root);
  scratch_.clear();
  scratch_.push_back(root);
  while (!scratch_.empty()) {
    const uint32_t id = scratch_.back();
    scratch_.pop_back();
    uint32_t c = pool_.links(id).first_child;
    while (c != kNoIndex) {
      const uint32_t next = pool_.links(c).next_sibling;
      if (pool_.links(c).kind == WindowKind::kPseudoSource) {
        pool_.Unlink(c);  // a vertex's distance is a fact: its pseudo-source survives as a root
      } else {
        scratch_.push_back(c);
      }
      c = next;
    }
    ++stats_.windows_deleted_one_split;
    pool_.Free(id);
  }
  ReleaseIfDone(parent);
}

}  // namespace geodex::ich
