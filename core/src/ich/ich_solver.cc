#include "ich/ich_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "absl/strings/str_format.h"

namespace geodex::ich {
namespace {

// Numerical policy (docs/numerics.md): every tolerance is relative to the geometry at hand.
// Filter ties keep the window: it is killed only when worse by more than this fraction of the
// distances compared (so a vertex distance set by the window's own parent never kills it).
constexpr double kFilterRelTol = 1e-12;
// The opposite vertex counts as seen by a window when its ray crosses within this fraction of the
// edge length of the interval (generous: a spurious second child is harmless, a missed one is not).
constexpr double kCoverRelTol = 1e-10;
// Windows narrower than this fraction of their edge carry no path that a neighbouring window or
// an endpoint vertex does not also carry.
constexpr double kTinyWindowRel = 1e-13;
// An image closer than this (relative to the edge) to the edge's line sends rays along the edge,
// never into the face.
constexpr double kGrazingRel = 1e-13;
// Lemma 1 treats distances or crossing points this close as ties and then keeps both children.
constexpr double kSplitTieRel = 1e-12;
// Windows whose keys differ by less than this fraction of the mean edge length are processed in
// any (deterministic) order: see WindowQueue.
constexpr double kQueueResolutionEdges = 0.5;
// Cancellation is polled every this many dequeued windows.
constexpr uint32_t kCancelPollInterval = 1024;

constexpr double kPi = 3.14159265358979323846;

inline double Hypot(double x, double y) { return std::sqrt(x * x + y * y); }

// Where the ray from image (ix, iy) through edge point (b, 0) meets the segment from p to p + w,
// as a parameter in [0, 1] (clamped: the caller knows the ray hits that segment).
inline double RayHitParam(double ix, double iy, double b, double px, double py, double wx,
                          double wy) {
  const double dx = b - ix, dy = -iy;
  const double denom = wx * dy - wy * dx;
  const double numer = (ix - px) * dy - (iy - py) * dx;
  // I + s D = P + t W, crossed with D: (I - P) x D = t (W x D), with a x b = a.x b.y - a.y b.x.
  double t = denom != 0 ? numer / denom : 0.0;
  if (!(t > 0)) t = 0;  // also catches NaN
  if (t > 1) t = 1;
  return t;
}

}  // namespace

IchSolver::IchSolver(const TriangleMesh& mesh, const GeodesicOptions& options, double key_cap)
    : mesh_(mesh),
      options_(options),
      key_cap_(std::min(key_cap, options.max_distance)),
      keep_tree_(options.method == Method::kIch),
      pool_(keep_tree_) {
  if (options.lambda > 0) {
    const double scale = options.lambda_scale == LambdaScale::kMaxEdge ? mesh.MaxEdgeLength()
                                                                       : mesh.MeanEdgeLength();
    epsilon_ = options.lambda * scale;
  }
}

void IchSolver::Push(uint32_t id, double key) {
  queue_.Push({key, id, keep_tree_ ? pool_.links(id).generation : 0});
}

void IchSolver::SeedVertex(uint32_t v, uint32_t label) {
  if (dist_[v] <= 0) return;  // the same vertex given twice: the first label wins
  dist_[v] = 0;
  label_[v] = label;
  origin_[v] = VertexOrigin{kNoIndex, v, 0, 0};
  const uint32_t id = NewPseudoSourceWindow(v, 0, label, 0);
  ++stats_.pseudo_sources;
  Push(id, 0);
}

uint32_t IchSolver::NewPseudoSourceWindow(uint32_t vertex, double sigma, uint32_t source,
                                          uint32_t level) {
  const uint32_t id = pool_.Allocate();
  Window& w = pool_[id];
  pool_.SetKind(id, WindowKind::kPseudoSource, WindowSide::kInitial);
  w.element = vertex;
  w.sigma = sigma;
  w.b0 = w.b1 = w.ix = w.iy = 0;
  w.pseudo_source = vertex;
  w.source = source;
  w.level = level;
  return id;
}

void IchSolver::SeedFacePoint(const ResolvedSource& s) {
  // A root window so the seed's children have a parent (kept for the tree's sake).
  const uint32_t root = NewPseudoSourceWindow(kNoIndex, 0, s.label, 0);
  MarkProcessed(root);
  EmitFromPointInFace(root, 3 * s.face, s.px, s.py, 0, kNoIndex, s.label);
  ReleaseIfDone(root);
}

void IchSolver::EmitFromPointInFace(uint32_t parent, uint32_t frame_edge, double px, double py,
                                    double sigma, uint32_t pseudo_source, uint32_t source) {
  // Paths from a point in (or on the border of) a face: its vertices are reached straight, and
  // windows leave through its edges. On an edge, the matching window would graze and is dropped;
  // the neighbouring face is seeded by the caller.
  const uint32_t f = TriangleMesh::FaceOf(frame_edge);
  const double cx[3] = {0, mesh_.Length(3 * f), mesh_.OppX(3 * f)};
  const double cy[3] = {0, 0, mesh_.OppY(3 * f)};
  {
    // The point given in frame_edge's frame, re-expressed in the frame of half-edge 3f.
    const int k = static_cast<int>(frame_edge % 3), k1 = (k + 1) % 3;
    const double len = mesh_.Length(frame_edge);
    const double ux = (cx[k1] - cx[k]) / len, uy = (cy[k1] - cy[k]) / len;
    const double x = px, y = py;
    px = cx[k] + x * ux - y * uy;
    py = cy[k] + x * uy + y * ux;
  }
  if (!face_target_head_.empty() && face_target_head_[f] != kNoIndex) {
    // A target in this very face is reached straight from the point.
    const uint32_t source_label = pool_[parent].source;
    OfferPointToTargets(f, px, py, sigma, source_label, pseudo_source, 3 * f, px, py);
  }
  for (int k = 0; k < 3; ++k) {
    const uint32_t h = 3 * f + k;
    const int k1 = (k + 1) % 3;
    const double len = mesh_.Length(h);
    const double ux = (cx[k1] - cx[k]) / len, uy = (cy[k1] - cy[k]) / len;
    // The point in h's frame (+y towards the face).
    const double qx = (px - cx[k]) * ux + (py - cy[k]) * uy;
    const double qy = -(px - cx[k]) * uy + (py - cy[k]) * ux;
    UpdateVertex(mesh_.From(h), sigma + Hypot(qx, qy), parent, h, qx, qy);
    const uint32_t t = mesh_.Twin(h);
    if (t == kNoIndex) continue;
    // In the twin's frame the point lies behind the edge: (len - x, -y).
    MakeInterval(parent, t, 0, len, len - qx, -qy, WindowSide::kInitial, pseudo_source, sigma,
                 source);
  }
}

bool IchSolver::UpdateVertex(uint32_t v, double d, uint32_t parent, uint32_t half_edge, double ix,
                             double iy) {
  if (!(d < dist_[v])) return false;
  const Window& p = pool_[parent];
  dist_[v] = d;
  straight_through_[v] = 0;
  if (!vertex_is_target_.empty() && vertex_is_target_[v]) targets_dirty_ = true;
  label_[v] = p.source;
  origin_[v] = VertexOrigin{half_edge, p.kind == WindowKind::kPseudoSource ? p.element
                                                                            : p.pseudo_source,
                            ix, iy};
  // Paths bend only at saddle and boundary vertices (P4); with lambda > 0 every vertex also passes
  // its distance along its edges, so it gets a (relax-only) pseudo-source window too.
  if (mesh_.IsPseudoSourceCandidate(v) || epsilon_ > 0) {
    if (d > options_.max_distance) return true;
    const uint32_t level = pool_[parent].level + 1;
    const uint32_t id = NewPseudoSourceWindow(v, d, pool_[parent].source, level);
    stats_.max_level = std::max(stats_.max_level, level);
    if (keep_tree_) pool_.AddChild(parent, id);
    ++stats_.pseudo_sources;
    Push(id, VertexKey(v, d));
  }
  return true;
}

void IchSolver::RelaxNeighbors(uint32_t v, double d, uint32_t source) {
  for (uint32_t i = mesh_.NeighborBegin(v); i < mesh_.NeighborEnd(v); ++i) {
    const uint32_t u = mesh_.NeighborVertex(i);
    const double du = d + mesh_.NeighborLength(i);
    if (!(du < dist_[u])) continue;
    ++stats_.edge_relaxations;
    dist_[u] = du;
    straight_through_[u] = 0;
    if (!vertex_is_target_.empty() && vertex_is_target_[u]) targets_dirty_ = true;
    label_[u] = source;
    origin_[u] = VertexOrigin{kNoIndex, v, 0, 0};
    if ((mesh_.IsPseudoSourceCandidate(u) || epsilon_ > 0) && du <= options_.max_distance) {
      // The neighbour becomes a pseudo-source of its own (a root: it does not depend on any
      // interval window's survival).
      const uint32_t id = NewPseudoSourceWindow(u, du, source, 0);
      ++stats_.pseudo_sources;
      Push(id, VertexKey(u, du));
    }
  }
}

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

void IchSolver::MakeInterval(uint32_t parent, uint32_t he, double b0, double b1, double ix,
                             double iy, WindowSide side, uint32_t pseudo_source, double sigma,
                             uint32_t source) {
  const double len = mesh_.Length(he);
  if (b1 - b0 <= kTinyWindowRel * len) return;
  // P3: a shortest path crosses each face at most once, so no useful sequence is deeper than the
  // face count (this is what bounds the tree when the filter is switched off).
  if (pool_[parent].level + 1 > mesh_.face_count()) return;
  if (iy > -kGrazingRel * len) return;
  ++stats_.windows_created;
  double key;
  if (options_.use_filter) {
    double ra, rb;
    if (!TrimByEndpoints(he, &b0, &b1, ix, iy, sigma, &ra, &rb) ||
        IsFiltered(he, b0, b1, ix, iy, sigma, ra, rb, side, 0)) {
      ++stats_.windows_filtered_at_creation;
      return;
    }
    if (epsilon_ > 0 && IsFiltered(he, b0, b1, ix, iy, sigma, ra, rb, side, epsilon_)) {
      ++stats_.windows_filtered_overfilter;
      return;
    }
    // IntervalKey, from the distances already at hand (bit for bit the same).
    key = ix < b0 ? sigma + ra : ix > b1 ? sigma + rb : sigma - iy;
  } else {
    key = IntervalKey(b0, b1, ix, iy, sigma);
  }
  if (heuristic_) key = WindowKey(he, b0, b1, ix, iy, sigma, key);
  if (key > key_cap_) return;
  const uint32_t id = pool_.Allocate();
  const uint32_t level = pool_[parent].level + 1;
  Window& w = pool_[id];
  pool_.SetKind(id, WindowKind::kInterval, side);
  w.element = he;
  w.b0 = b0;
  w.b1 = b1;
  w.ix = ix;
  w.iy = iy;
  w.sigma = sigma;
  w.pseudo_source = pseudo_source;
  w.source = source;
  w.level = level;
  stats_.max_level = std::max(stats_.max_level, level);
  if (keep_tree_) pool_.AddChild(parent, id);
  Push(id, key);
}

void IchSolver::MarkProcessed(uint32_t id) {
  if (keep_tree_) pool_.links(id).state = WindowState::kProcessed;
}

void IchSolver::ReleaseIfDone(uint32_t id) {
  if (!keep_tree_) {  // no tree: nothing can refer to a processed window
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

void IchSolver::ProcessPseudoSource(uint32_t id) {
  const Window w = pool_[id];
  const uint32_t v = w.element;
  if (w.sigma != dist_[v]) {  // superseded by a shorter path to v
    MarkProcessed(id);
    ReleaseIfDone(id);
    return;
  }
  MarkProcessed(id);
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
      if (t == kNoIndex) continue;
      const double len = mesh_.Length(opposite);
      MakeInterval(id, t, 0, len, len - mesh_.OppX(opposite), -mesh_.OppY(opposite),
                   WindowSide::kInitial, v, w.sigma, w.source);
    }
  }
  ReleaseIfDone(id);
}

double IchSolver::IntervalKey(double b0, double b1, double ix, double iy, double sigma) {
  // Smallest distance any point of the interval can get through the window.
  if (ix < b0) return sigma + Hypot(b0 - ix, iy);
  if (ix > b1) return sigma + Hypot(b1 - ix, iy);
  return sigma - iy;
}

void IchSolver::SpawnShadowWindows(uint32_t id, uint32_t v, double sigma, uint32_t source) {
  // The direction back towards the image, as an angle in v's fan: v was the opposite vertex of
  // half-edge h, whose face has its corner at v on half-edge Prev(h) (v -> start of h).
  const VertexOrigin& o = origin_[v];
  const uint32_t h = o.half_edge;
  const uint32_t corner_in = TriangleMesh::Prev(h);
  const double x3 = mesh_.OppX(h), y3 = mesh_.OppY(h);
  const double ax = -x3, ay = -y3;                // v -> start of h
  const double dx = o.ix - x3, dy = o.iy - y3;   // v -> image
  const double back =
      mesh_.CornerStartAngle(corner_in) + std::atan2(std::abs(ax * dy - ay * dx), ax * dx + ay * dy);
  // Geodesics through a saddle make angles >= pi on both sides (P4): new paths leave v only in the
  // sector [back + pi, back + total - pi], empty or nearly so for a flat vertex.
  const double total = mesh_.AngleSum(v);
  const double lo = back + kPi, hi = back + total - kPi;
  if (!(hi > lo)) return;
  for (const uint32_t* c = mesh_.CornersBegin(v); c != mesh_.CornersEnd(v); ++c) {
    const uint32_t corner = *c;
    const uint32_t opposite = TriangleMesh::Next(corner);
    const uint32_t t = mesh_.Twin(opposite);
    if (t == kNoIndex) continue;
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
      MakeInterval(id, t, len - x1, len - x0, len - px, -py, WindowSide::kInitial, v, sigma,
                   source);
    }
  }
}

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
                    (p[2] - a[2]) * (b[2] - a[2])) / len;
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
  if (s3 >= w.b0 && s3 <= w.b1) UpdateVertex(v3, w.sigma + Hypot(s3 - w.ix, w.iy), id, h, w.ix, w.iy);
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

void IchSolver::ProcessInterval(uint32_t id, double popped_key) {
  Window w = pool_[id];  // copy: the pool may grow below
  uint32_t generation = 0;
  if (keep_tree_) {
    const WindowLinks& links = pool_.links(id);
    generation = links.generation;
    // ReleaseIfDone below walks up to the parent; start fetching its links now.
    if (links.parent != kNoIndex) pool_.PrefetchLinks(links.parent);
  }
  const uint32_t h = w.element;
  // With over-filtering (lambda > 0), test the window again: vertex distances have dropped since
  // it was made. In exact mode this is skipped: measured on gargoyle, armadillo and a terrain it
  // drops under 0.05% of the windows (every window was trimmed and tested when made, and the
  // vertex ahead is rarely reached in between) for ~17% of the instructions. Skipping a filter
  // never costs exactness, only work.
  if (options_.use_filter && epsilon_ > 0) {
    // Trim again, and if that raised its key, queue it again so windows keep being processed in
    // distance order.
    const double b0 = w.b0, b1 = w.b1;
    double ra, rb;
    if (!TrimByEndpoints(h, &w.b0, &w.b1, w.ix, w.iy, w.sigma, &ra, &rb)) {
      ++stats_.windows_filtered_at_pop;
      MarkProcessed(id);
      ReleaseIfDone(id);
      return;
    }
    if (w.b0 != b0 || w.b1 != b1) {
      pool_[id].b0 = w.b0;
      pool_[id].b1 = w.b1;
      double key = IntervalKey(w.b0, w.b1, w.ix, w.iy, w.sigma);
      if (heuristic_) key = WindowKey(h, w.b0, w.b1, w.ix, w.iy, w.sigma, key);
      if (key > popped_key * (1 + kFilterRelTol)) {
        Push(id, key);
        return;
      }
    }
  }
  if (options_.use_filter && epsilon_ > 0 &&
      (IsFiltered(h, w.b0, w.b1, w.ix, w.iy, w.sigma, Hypot(w.b0 - w.ix, w.iy),
                  Hypot(w.b1 - w.ix, w.iy), w.side, 0) ||
       IsFiltered(h, w.b0, w.b1, w.ix, w.iy, w.sigma, Hypot(w.b0 - w.ix, w.iy),
                  Hypot(w.b1 - w.ix, w.iy), w.side, epsilon_))) {
    ++stats_.windows_filtered_at_pop;
    MarkProcessed(id);
    ReleaseIfDone(id);
    return;
  }
  MarkProcessed(id);
  ++stats_.windows_processed;
  if (mesh_.FaceDegenerate(TriangleMesh::FaceOf(h))) {
    PassThroughDegenerate(id, w);
    ReleaseIfDone(id);
    return;
  }

  if (!face_target_head_.empty() && face_target_head_[TriangleMesh::FaceOf(h)] != kNoIndex) {
    OfferWindowToTargets(h, w);
  }
  const double len = mesh_.Length(h);
  const double x3 = mesh_.OppX(h), y3 = mesh_.OppY(h);
  const uint32_t v3 = mesh_.Opposite(h);
  // Where the ray from the image to the opposite vertex crosses this edge.
  const double cross_x = w.ix + (x3 - w.ix) * (-w.iy) / (y3 - w.iy);
  const double cover_tol = kCoverRelTol * len;
  const bool sees_v3 = cross_x >= w.b0 - cover_tol && cross_x <= w.b1 + cover_tol;
  bool make_left = cross_x > w.b0 - cover_tol;  // some rays pass left of v3
  bool make_right = cross_x < w.b1 + cover_tol;
  bool v3_improved = false;

  if (sees_v3) {
    const double d3 = w.sigma + Hypot(x3 - w.ix, y3 - w.iy);
    v3_improved = UpdateVertex(v3, d3, id, h, w.ix, w.iy);
    if (options_.use_one_angle_one_split) {
      // Lemma 1 (one angle one split): of the windows on this directed edge that see v3, only the
      // one giving v3 the smallest distance keeps both children; a loser keeps the child on the
      // side where its own ray to v3 crosses the edge relative to the winner's.
      SplitRecord& best = split_[h];
      const double tie = kSplitTieRel * d3;
      if (d3 < best.distance - tie) {
        if (keep_tree_) {
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
            return;
          }
          split_owner_[h] = SplitOwner{id, generation};
        }
        best.distance = d3;
        best.cross_x = cross_x;
      } else if (d3 > best.distance + tie) {
        if (cross_x > best.cross_x + cover_tol) {
          if (make_left) ++stats_.children_skipped_one_split;
          make_left = false;
        } else if (cross_x < best.cross_x - cover_tol) {
          if (make_right) ++stats_.children_skipped_one_split;
          make_right = false;
        }
      }
    }
  }

  // When v3's best path runs straight through it with windows continuing on both sides, those
  // windows already cover every direction within pi of the incoming ray: v3's own windows are
  // needed only in its shadow sector (see ProcessPseudoSource).
  // On regular grids the ray to v3 often runs exactly along the boundary between two windows of
  // the same image (a ray through an earlier vertex): each covers one side. Record the sides a
  // window covers (bit 1: rays pass left of v3, bit 2: right); the straight continuation is
  // complete once both sides are covered by the image that gives v3 its distance.
  if (sees_v3 && mesh_.Twin(TriangleMesh::Prev(h)) != kNoIndex &&
      mesh_.Twin(TriangleMesh::Next(h)) != kNoIndex) {
    const uint8_t sides = static_cast<uint8_t>((make_left && cross_x > w.b0 ? 1 : 0) |
                                               (make_right && cross_x < w.b1 ? 2 : 0));
    if (v3_improved) {
      straight_through_[v3] = sides;
    } else {
      // A tie with the same image on the same edge completes the other side.
      const VertexOrigin& o = origin_[v3];
      const double d3 = w.sigma + Hypot(x3 - w.ix, y3 - w.iy);
      const double tol = kSplitTieRel * (d3 + len);
      if (o.half_edge == h && std::abs(d3 - dist_[v3]) <= tol && std::abs(o.ix - w.ix) <= tol &&
          std::abs(o.iy - w.iy) <= tol) {
        straight_through_[v3] |= sides;
      }
    }
  }

  if (make_left) {
    // Child on the edge v1 -> v3 (v1 = this edge's start), in the twin's frame.
    const uint32_t e = TriangleMesh::Prev(h);  // v3 -> v1 in this face
    const uint32_t t = mesh_.Twin(e);
    const double el = mesh_.Length(e);
    const double t0 = RayHitParam(w.ix, w.iy, w.b0, 0, 0, x3, y3);
    const double t1 = sees_v3 ? 1.0 : RayHitParam(w.ix, w.iy, w.b1, 0, 0, x3, y3);
    // Endpoint distances when the child reaches a vertex.
    // Endpoint reached along the interval's end ray: in exact arithmetic already set by the same
    // path, so only a real gain counts (a last-bit "gain" would hide a straight-through path).
    const double d1 = w.sigma + Hypot(w.ix, w.iy);
    if (t0 <= 0 && w.b0 <= kTinyWindowRel * len && d1 < dist_[mesh_.From(h)] * (1 - kFilterRelTol)) {
      UpdateVertex(mesh_.From(h), d1, id, h, w.ix, w.iy);
    }
    if (t != kNoIndex && t1 > t0) {
      const double ux = x3 / el, uy = y3 / el;
      const double nix = w.ix * ux + w.iy * uy;
      const double niy = -w.ix * uy + w.iy * ux;
      MakeInterval(id, t, t0 * el, t1 * el, nix, niy, WindowSide::kLeft, w.pseudo_source, w.sigma,
                   w.source);
    }
  }
  if (make_right) {
    // Child on the edge v3 -> v2, in the twin's frame (origin v3).
    const uint32_t e = TriangleMesh::Next(h);  // v2 -> v3 in this face
    const uint32_t t = mesh_.Twin(e);
    const double el = mesh_.Length(e);
    const double wx = len - x3, wy = -y3;
    const double t0 = sees_v3 ? 0.0 : RayHitParam(w.ix, w.iy, w.b0, x3, y3, wx, wy);
    const double t1 = RayHitParam(w.ix, w.iy, w.b1, x3, y3, wx, wy);
    const double d2 = w.sigma + Hypot(len - w.ix, w.iy);
    if (t1 >= 1 && w.b1 >= len * (1 - kTinyWindowRel) && d2 < dist_[mesh_.To(h)] * (1 - kFilterRelTol)) {
      UpdateVertex(mesh_.To(h), d2, id, h, w.ix, w.iy);
    }
    if (t != kNoIndex && t1 > t0) {
      const double ux = wx / el, uy = wy / el;
      const double rx = w.ix - x3, ry = w.iy - y3;
      const double nix = rx * ux + ry * uy;
      const double niy = -rx * uy + ry * ux;
      MakeInterval(id, t, t0 * el, t1 * el, nix, niy, WindowSide::kRight, w.pseudo_source, w.sigma,
                   w.source);
    }
  }
  ReleaseIfDone(id);
}

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
    if (via_vertex != kNoIndex) {
      Offer(t, placement, dd, label, VertexOrigin{kNoIndex, via_vertex, 0, 0}, 0, 0);
    } else {
      Offer(t, placement, dd, label, VertexOrigin{frame_edge, kNoIndex, fx, fy}, at.px, at.py);
    }
  }
}

double IchSolver::TargetsBound() {
  if (!targets_dirty_) return targets_bound_;
  targets_dirty_ = false;
  double bound = 0;
  for (uint32_t t = 0; t < targets_->size(); ++t) {
    double d = (*target_results_)[t].distance;
    for (uint32_t v : (*targets_)[t].vertices) d = std::min(d, dist_[v]);
    bound = std::max(bound, d);
  }
  targets_bound_ = bound;
  return bound;
}

absl::Status IchSolver::Solve(const std::vector<ResolvedSource>& sources, DistanceField* out) {
  return SolveForTargets(sources, {}, false, false, out, nullptr);
}

absl::Status IchSolver::SolveForTargets(const std::vector<ResolvedSource>& sources,
                                        const std::vector<ResolvedTarget>& targets,
                                        bool use_heuristic, bool stop_early, DistanceField* out,
                                        std::vector<TargetResult>* results) {
  const auto start = std::chrono::steady_clock::now();
  if (results != nullptr) {
    targets_ = &targets;
    target_results_ = results;
    results->assign(targets.size(), TargetResult{});
    stop_early_ = stop_early;
    heuristic_ = use_heuristic && targets.size() == 1;
    face_target_head_.assign(mesh_.face_count(), kNoIndex);
    vertex_is_target_.assign(mesh_.vertex_count(), 0);
    face_target_next_.clear();
    face_target_entry_.clear();
    for (uint32_t t = 0; t < targets.size(); ++t) {
      for (uint32_t v : targets[t].vertices) vertex_is_target_[v] = 1;
      for (uint32_t k = 0; k < targets[t].placements.size(); ++k) {
        const uint32_t f = targets[t].placements[k].face;
        face_target_entry_.push_back({t, k});
        face_target_next_.push_back(face_target_head_[f]);
        face_target_head_[f] = static_cast<uint32_t>(face_target_entry_.size() - 1);
      }
    }
    targets_dirty_ = true;
  }
  const uint32_t nv = mesh_.vertex_count();
  dist_.assign(nv, kUnreachable);
  label_.assign(nv, kNoIndex);
  origin_.assign(nv, VertexOrigin{});
  straight_through_.assign(nv, 0);
  if (options_.use_one_angle_one_split) {
    split_.assign(3 * size_t{mesh_.face_count()}, SplitRecord{});
    if (keep_tree_) split_owner_.assign(3 * size_t{mesh_.face_count()}, SplitOwner{});
  }
  queue_.Reset(kQueueResolutionEdges * mesh_.MeanEdgeLength());
  queue_.reserve(4 * size_t{nv});

  for (const ResolvedSource& s : sources) {
    if (s.is_vertex) {
      SeedVertex(s.vertex, s.label);
    } else {
      SeedFacePoint(s);
    }
  }

  absl::Status status = absl::OkStatus();
  uint32_t polls = 0;
  while (!queue_.empty()) {
    const QueueEntry e = queue_.Pop();
    // The next window is most likely the new top: fetch it while this one is processed.
    if (const QueueEntry* next = queue_.Peek()) pool_.Prefetch(next->window);
    // Only the paper's tree deletes queued windows (Lemma 1's subtrees); without it every entry
    // is a live queued window, and its links are not even read.
    if (keep_tree_ && (pool_.links(e.window).generation != e.generation ||
                       pool_.links(e.window).state != WindowState::kQueued)) {
      continue;  // deleted (Lemma 1) or recycled since it was queued
    }
    // Every queued key is at least LowerBound() (entries of near-equal keys pop in any order).
    const double floor = queue_.LowerBound();
    if (floor > options_.max_distance) break;
    // Every path not yet accounted for is at least as long as this key (keys are lower bounds,
    // and never decrease along a path): targets whose distance is at most the key are final.
    if (target_results_ != nullptr && stop_early_ && floor >= TargetsBound()) break;
    if (++polls == kCancelPollInterval) {
      polls = 0;
      if (options_.cancel != nullptr && options_.cancel->IsCancelled()) {
        status = absl::CancelledError("geodesic solve cancelled");
        break;
      }
    }
    if (options_.max_windows != 0 && stats_.windows_created > options_.max_windows) {
      status = absl::ResourceExhaustedError(absl::StrFormat(
          "window budget exceeded: %d windows created (limit %d); use a larger budget, a "
          "max_distance, or lambda > 0",
          stats_.windows_created, options_.max_windows));
      break;
    }
    if (pool_[e.window].kind == WindowKind::kPseudoSource) {
      ProcessPseudoSource(e.window);
    } else {
      ProcessInterval(e.window, e.key);
    }
  }

  stats_.peak_live_windows = pool_.peak_live();
  stats_.peak_bytes = pool_.CapacityBytes() + queue_.CapacityBytes() +
                      split_.capacity() * sizeof(SplitRecord) +
                      split_owner_.capacity() * sizeof(SplitOwner) +
                      nv * (sizeof(double) + sizeof(uint32_t) + sizeof(VertexOrigin));
  if (!status.ok()) return status;
  if (std::isfinite(options_.max_distance)) {
    for (uint32_t v = 0; v < nv; ++v) {
      if (dist_[v] > options_.max_distance) {
        dist_[v] = kUnreachable;
        label_[v] = kNoIndex;
        origin_[v] = VertexOrigin{};
      }
    }
  }
  if (target_results_ != nullptr) {
    for (uint32_t t = 0; t < targets_->size(); ++t) {
      TargetResult& r = (*target_results_)[t];
      for (uint32_t v : (*targets_)[t].vertices) {
        if (dist_[v] < r.distance) {
          r.distance = dist_[v];
          r.label = label_[v];
          r.vertex = v;
        }
      }
    }
  }
  out->internal_distance = std::move(dist_);
  out->internal_source = std::move(label_);
  out->internal_origin = std::move(origin_);
  stats_.solve_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  out->stats = stats_;
  return absl::OkStatus();
}

}  // namespace geodex::ich
