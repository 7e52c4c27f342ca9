// Pseudo-sources: saddle, boundary and source vertices, where shortest paths may bend (P4).

#include <algorithm>
#include <cmath>

#include "ich/ich_solver.h"
#include "ich/numerics.h"

namespace geodex::ich {

uint32_t IchSolver::NewPointWindow(WindowKind kind, uint32_t element, uint32_t pseudo_source,
                                   double sigma, uint32_t source, uint32_t level) {
  const uint32_t id = pool_.Allocate();
  Window& w = pool_[id];
  pool_.SetKind(id, kind, WindowSide::kInitial);
  w.element = element;
  w.sigma = sigma;
  w.b0 = w.b1 = w.ix = w.iy = 0;
  w.pseudo_source = pseudo_source;
  w.source = source;
  w.level = level;
  return id;
}

void IchSolver::ProcessPseudoSource(uint32_t id) {
  const Window w = pool_[id];
  const uint32_t v = w.element;
  if (w.sigma != dist_[v]) {  // superseded by a shorter path to v
    pool_.MarkProcessed(id);
    ReleaseIfDone(id);
    return;
  }
  pool_.MarkProcessed(id);
  if (!face_target_head_.empty()) {
    // Paths to a target point may bend here and then run straight inside a face around v.
    for (const uint32_t* c = mesh_.CornersBegin(v); c != mesh_.CornersEnd(v); ++c) {
      const uint32_t f = TriangleMesh::FaceOf(*c);
      if (face_target_head_[f] == kNoIndex) continue;
      double vx, vy;
      const int k = static_cast<int>(*c % 3);
      vx = k == 0 ? 0 : k == 1 ? mesh_.Length(3 * f) : mesh_.OppX(3 * f);
      vy = k == 2 ? mesh_.OppY(3 * f) : 0;
      OfferPointToTargets(f, vx, vy, w.sigma, w.source, v, kNoIndex, 0, 0);
    }
  }
  // Neighbours first: the filter of the windows below then already sees their distances.
  RelaxNeighbors(v, w.sigma, w.source);
  if (regions_ != nullptr && regions_->point_count() > 0) RelaxChainEnds(v, w.sigma, w.source);
  // Sources (distance 0) and saddle/boundary vertices spawn windows; with lambda > 0 other
  // vertices only pass their distance along edges.
  const bool spawns_windows = mesh_.IsPseudoSourceCandidate(v) || w.sigma == 0;
  if (spawns_windows && straight_through_[v] == 3 && mesh_.HasClosedFan(v)) {
    ++stats_.pseudo_sources_shadow_only;
    SpawnShadowWindows(id, v, w.sigma, w.source);
  } else if (spawns_windows) {
    ++stats_.pseudo_sources_full_fan;
    for (const uint32_t* c = mesh_.CornersBegin(v); c != mesh_.CornersEnd(v); ++c) {
      const uint32_t corner = *c;
      if (mesh_.FaceDegenerate(TriangleMesh::FaceOf(corner))) {
        EmitAcrossDegenerate(id, corner, w.sigma, w.source);
        continue;
      }
      const uint32_t opposite = TriangleMesh::Next(corner);  // the edge facing v in this face
      const uint32_t t = mesh_.Twin(opposite);
      const double len = mesh_.Length(opposite);
      if (t == kNoIndex) {
        if (regions_ != nullptr) {
          ReachBoundary(opposite, 0, len, len - mesh_.OppX(opposite), -mesh_.OppY(opposite),
                        w.sigma, w.source, v);
        }
        continue;
      }
      MakeInterval(id, t, 0, len, len - mesh_.OppX(opposite), -mesh_.OppY(opposite),
                   WindowSide::kInitial, v, w.sigma, w.source);
    }
  }
  ReleaseIfDone(id);
}

void IchSolver::SpawnShadowWindows(uint32_t id, uint32_t v, double sigma, uint32_t source) {
  // The direction back towards the image, as an angle in v's fan: v was the opposite vertex of
  // half-edge h, whose face has its corner at v on half-edge Prev(h) (v -> start of h).
  const VertexOrigin& o = origin_[v];
  const uint32_t h = o.half_edge;
  const uint32_t corner_in = TriangleMesh::Prev(h);
  const double x3 = mesh_.OppX(h), y3 = mesh_.OppY(h);
  const double ax = -x3, ay = -y3;              // v -> start of h
  const double dx = o.ix - x3, dy = o.iy - y3;  // v -> image
  const double back = mesh_.CornerStartAngle(corner_in) +
                      std::atan2(std::abs(ax * dy - ay * dx), ax * dx + ay * dy);
  // Geodesics through a saddle make angles >= pi on both sides (P4): new paths leave v only in the
  // sector [back + pi, back + total - pi], empty or nearly so for a flat vertex.
  const double total = mesh_.AngleSum(v);
  const double lo = back + kPi, hi = back + total - kPi;
  if (!(hi > lo)) return;
  for (const uint32_t* c = mesh_.CornersBegin(v); c != mesh_.CornersEnd(v); ++c) {
    const uint32_t corner = *c;
    const uint32_t opposite = TriangleMesh::Next(corner);
    const uint32_t t = mesh_.Twin(opposite);
    if (t == kNoIndex && regions_ == nullptr) continue;
    const double start = mesh_.CornerStartAngle(corner), span = mesh_.CornerAngle(corner);
    // The sector may wrap around the fan: test it shifted by -total, 0 and +total.
    for (int wrap = -1; wrap <= 1; ++wrap) {
      const double s0 = std::max(lo + wrap * total, start) - start;
      const double s1 = std::min(hi + wrap * total, start + span) - start;
      if (!(s1 > s0)) continue;
      // Rays from v at angles s0..s1 (from the corner's first edge, v -> To(corner)) meet the
      // opposite edge; in its frame v is at (px, py) and To(corner) at the origin.
      const double len = mesh_.Length(opposite);
      const double px = mesh_.OppX(opposite), py = mesh_.OppY(opposite);
      const double base = std::atan2(-py, -px);
      auto hit = [&](double a) {
        const double ux = std::cos(base + a), uy = std::sin(base + a);
        if (uy >= 0) return a < 0.5 * span ? 0.0 : len;
        const double x = px + ux * (py / -uy);
        return std::min(len, std::max(0.0, x));
      };
      const double x0 = s0 <= 0 ? 0.0 : hit(s0);
      const double x1 = s1 >= span ? len : hit(s1);
      // In the twin's frame positions run the other way.
      if (t == kNoIndex) {
        ReachBoundary(opposite, len - x1, len - x0, len - px, -py, sigma, source, v);
      } else {
        MakeInterval(id, t, len - x1, len - x0, len - px, -py, WindowSide::kInitial, v, sigma,
                     source);
      }
    }
  }
}

}  // namespace geodex::ich
