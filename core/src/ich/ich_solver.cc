// The propagation: seeds, the main loop, interval windows crossing a face, vertex updates.
// The rules it applies live in files named after them (filter_theorem.cc, one_angle_one_split.cc,
// pseudo_sources.cc, degenerate_faces.cc, astar_key.cc, targets.cc, window_tree.cc).

#include "ich/ich_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "absl/strings/str_format.h"
#include "geodex/limits.h"
#include "ich/numerics.h"

namespace geodex::ich {

namespace {
std::unique_ptr<SolveWorkspace> AcquireWorkspace(const TriangleMesh& mesh) {
  return mesh.workspaces() != nullptr ? mesh.workspaces()->Acquire()
                                      : std::make_unique<SolveWorkspace>();
}
}  // namespace

IchSolver::IchSolver(const TriangleMesh& mesh, const GeodesicOptions& options, double key_cap)
    : workspace_(AcquireWorkspace(mesh)),
      mesh_(mesh),
      options_(options),
      key_cap_(std::min(key_cap, options.max_distance)),
      face_target_head_(workspace_->face_target_head),
      face_target_next_(workspace_->face_target_next),
      face_target_entry_(workspace_->face_target_entry),
      vertex_is_target_(workspace_->vertex_is_target),
      dist_(workspace_->dist),
      label_(workspace_->label),
      origin_(workspace_->origin),
      straight_through_(workspace_->straight_through),
      split_(workspace_->split),
      split_owner_(workspace_->split_owner),
      pool_(workspace_->pool),
      queue_(workspace_->queue),
      scratch_(workspace_->scratch) {
  workspace_->Prepare(mesh, /*with_links=*/options.method == Method::kIch,
                      /*with_split_owner=*/options.method == Method::kIch);
  if (options.lambda > 0) {
    const double scale = options.lambda_scale == LambdaScale::kMaxEdge ? mesh.MaxEdgeLength()
                                                                       : mesh.MeanEdgeLength();
    epsilon_ = options.lambda * scale;
  }
}

IchSolver::~IchSolver() {
  if (mesh_.workspaces() != nullptr) mesh_.workspaces()->Release(std::move(workspace_));
}

void IchSolver::Push(uint32_t id, double key) { queue_.Push({key, id, pool_.generation(id)}); }

void IchSolver::SeedVertex(uint32_t v, uint32_t label) {
  if (dist_[v] <= 0) return;  // the same vertex given twice: the first label wins
  if (dist_[v] == kUnreachable) TouchVertex(v);
  dist_[v] = 0;
  label_[v] = label;
  origin_[v] = VertexOrigin{kNoIndex, v, 0, 0};
  const uint32_t id = NewPseudoSourceWindow(v, 0, label, 0);
  ++stats_.pseudo_sources;
  Push(id, 0);
  if (regions_ != nullptr) ShareWithCopies(v, 0, label);
}

void IchSolver::SeedFacePoint(const ResolvedSource& s) {
  // A root window so the seed's children have a parent (kept for the tree's sake).
  const uint32_t root = NewPseudoSourceWindow(kNoIndex, 0, s.label, 0);
  pool_.MarkProcessed(root);
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
  if (has_targets_ && face_target_head_[f] != kNoIndex) {
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
    if (t == kNoIndex) {
      if (regions_ != nullptr) {
        ReachBoundary(h, 0, len, len - qx, -qy, sigma, source, pseudo_source);
      }
      continue;
    }
    // In the twin's frame the point lies behind the edge: (len - x, -y).
    MakeInterval(parent, t, 0, len, len - qx, -qy, WindowSide::kInitial, pseudo_source, sigma,
                 source);
  }
}

bool IchSolver::UpdateVertex(uint32_t v, double d, uint32_t parent, uint32_t half_edge, double ix,
                             double iy) {
  if (!(d < dist_[v])) return false;
  const Window& p = pool_[parent];
  SetVertex(
      v, d, p.source,
      VertexOrigin{half_edge, p.kind == WindowKind::kPseudoSource ? p.element : p.pseudo_source, ix,
                   iy});
  if (regions_ != nullptr) ShareWithCopies(v, d, p.source);
  // Paths bend only at saddle and boundary vertices (P4); with lambda > 0 every vertex also passes
  // its distance along its edges, so it gets a (relax-only) pseudo-source window too.
  if (mesh_.IsPseudoSourceCandidate(v) || epsilon_ > 0) {
    if (d > options_.max_distance) return true;
    const uint32_t level = pool_[parent].level + 1;
    const uint32_t id = NewPseudoSourceWindow(v, d, pool_[parent].source, level);
    stats_.max_level = std::max(stats_.max_level, level);
    pool_.AddChild(parent, id);
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
    SetVertex(u, du, source, VertexOrigin{kNoIndex, v, 0, 0});
    if (regions_ != nullptr) ShareWithCopies(u, du, source);
    if ((mesh_.IsPseudoSourceCandidate(u) || epsilon_ > 0) && du <= options_.max_distance) {
      // The neighbour becomes a pseudo-source of its own (a root: it does not depend on any
      // interval window's survival).
      const uint32_t id = NewPseudoSourceWindow(u, du, source, 0);
      ++stats_.pseudo_sources;
      Push(id, VertexKey(u, du));
    }
  }
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
  pool_.AddChild(parent, id);
  Push(id, key);
}

double IchSolver::IntervalKey(double b0, double b1, double ix, double iy, double sigma) {
  // Smallest distance any point of the interval can get through the window.
  if (ix < b0) return sigma + Hypot(b0 - ix, iy);
  if (ix > b1) return sigma + Hypot(b1 - ix, iy);
  return sigma - iy;
}

// ProcessInterval's steps (docs/engine.md, "Processing an interval window"), each named; they are
// called once each from the one caller below and inlined there.

// Step 1, lambda > 0 only: the re-test of an over-filtered window when it is popped. Vertex
// distances may have dropped since the window was made, so it is trimmed (Lemma 2 by the edge's
// endpoints) and tested (Lemma 2 against the face's vertices, exact and over-filtered) again. In
// exact mode this is skipped: measured on gargoyle, armadillo and a terrain it drops under 0.05%
// of the windows (every window was trimmed and tested when made, and the vertex ahead is rarely
// reached in between) for ~17% of the instructions. Skipping a filter never costs exactness, only
// work.
[[gnu::always_inline]] inline IchSolver::PopRetest IchSolver::RetestOverFiltered(
    uint32_t id, Window* w, double popped_key) {
  const uint32_t h = w->element;
  const double b0 = w->b0, b1 = w->b1;
  double ra, rb;
  if (!TrimByEndpoints(h, &w->b0, &w->b1, w->ix, w->iy, w->sigma, &ra, &rb)) {
    return PopRetest::kDropped;
  }
  if (w->b0 != b0 || w->b1 != b1) {
    pool_[id].b0 = w->b0;
    pool_[id].b1 = w->b1;
    // Trimming raised its key: queue it again, so windows keep being processed in key order.
    double key = IntervalKey(w->b0, w->b1, w->ix, w->iy, w->sigma);
    if (heuristic_) key = WindowKey(h, w->b0, w->b1, w->ix, w->iy, w->sigma, key);
    if (key > popped_key * (1 + kFilterRelTol)) {
      Push(id, key);
      return PopRetest::kRequeued;
    }
  }
  const double ra0 = Hypot(w->b0 - w->ix, w->iy), rb0 = Hypot(w->b1 - w->ix, w->iy);
  if (IsFiltered(h, w->b0, w->b1, w->ix, w->iy, w->sigma, ra0, rb0, w->side, 0) ||
      IsFiltered(h, w->b0, w->b1, w->ix, w->iy, w->sigma, ra0, rb0, w->side, epsilon_)) {
    return PopRetest::kDropped;
  }
  return PopRetest::kKeep;
}

// Step 3, the straight-through bookkeeping. When v3's best path runs straight through it with
// windows continuing on both sides, those windows already cover every direction within pi of the
// incoming ray: v3's own windows are needed only in its shadow sector (see ProcessPseudoSource).
// On regular grids the ray to v3 often runs exactly along the boundary between two windows of the
// same image (a ray through an earlier vertex): each covers one side. Record the sides a window
// covers (bit 1: rays pass left of v3, bit 2: right); the straight continuation is complete once
// both sides are covered by the image that gives v3 its distance.
[[gnu::always_inline]] inline void IchSolver::RecordStraightThrough(const Window& w, uint32_t h,
                                                                    const Ahead& ahead) {
  if (mesh_.Twin(TriangleMesh::Prev(h)) == kNoIndex ||
      mesh_.Twin(TriangleMesh::Next(h)) == kNoIndex) {
    return;
  }
  const uint32_t v3 = ahead.v3;
  const uint8_t sides = static_cast<uint8_t>((ahead.make_left && ahead.cross_x > w.b0 ? 1 : 0) |
                                             (ahead.make_right && ahead.cross_x < w.b1 ? 2 : 0));
  if (ahead.v3_improved) {
    straight_through_[v3] = sides;
    return;
  }
  // A tie with the same image on the same edge completes the other side.
  const VertexOrigin& o = origin_[v3];
  const double d3 = w.sigma + Hypot(ahead.x3 - w.ix, ahead.y3 - w.iy);
  const double tol = kSplitTieRel * (d3 + ahead.len);
  if (o.half_edge == h && std::abs(d3 - dist_[v3]) <= tol && std::abs(o.ix - w.ix) <= tol &&
      std::abs(o.iy - w.iy) <= tol) {
    straight_through_[v3] |= sides;
  }
}

// Step 4a, the child on the left: on the edge v1 -> v3 (v1 = this edge's start), in the twin's
// frame, with v1's distance when the window reaches it along its end ray.
[[gnu::always_inline]] inline void IchSolver::MakeLeftChild(uint32_t id, const Window& w,
                                                            uint32_t h, const Ahead& ahead) {
  const double x3 = ahead.x3, y3 = ahead.y3, len = ahead.len;
  const uint32_t e = TriangleMesh::Prev(h);  // v3 -> v1 in this face
  const uint32_t t = mesh_.Twin(e);
  const double el = mesh_.Length(e);
  const double t0 = RayHitParam(w.ix, w.iy, w.b0, 0, 0, x3, y3);
  const double t1 = ahead.sees_v3 ? 1.0 : RayHitParam(w.ix, w.iy, w.b1, 0, 0, x3, y3);
  // Endpoint reached along the interval's end ray: in exact arithmetic already set by the same
  // path, so only a real gain counts (a last-bit "gain" would hide a straight-through path).
  const double d1 = w.sigma + Hypot(w.ix, w.iy);
  if (t0 <= 0 && w.b0 <= kTinyWindowRel * len && d1 < dist_[mesh_.From(h)] * (1 - kFilterRelTol)) {
    UpdateVertex(mesh_.From(h), d1, id, h, w.ix, w.iy);
  }
  if (t1 > t0) {
    const double ux = x3 / el, uy = y3 / el;
    const double nix = w.ix * ux + w.iy * uy;
    const double niy = -w.ix * uy + w.iy * ux;
    if (t != kNoIndex) {
      MakeInterval(id, t, t0 * el, t1 * el, nix, niy, WindowSide::kLeft, w.pseudo_source, w.sigma,
                   w.source);
    } else if (regions_ != nullptr) {
      ReachBoundary(e, t0 * el, t1 * el, nix, niy, w.sigma, w.source, w.pseudo_source);
    }
  }
}

// Step 4b, the child on the right: on the edge v3 -> v2, in the twin's frame (origin v3), with
// v2's distance when the window reaches it along its end ray.
[[gnu::always_inline]] inline void IchSolver::MakeRightChild(uint32_t id, const Window& w,
                                                             uint32_t h, const Ahead& ahead) {
  const double x3 = ahead.x3, y3 = ahead.y3, len = ahead.len;
  const uint32_t e = TriangleMesh::Next(h);  // v2 -> v3 in this face
  const uint32_t t = mesh_.Twin(e);
  const double el = mesh_.Length(e);
  const double wx = len - x3, wy = -y3;
  const double t0 = ahead.sees_v3 ? 0.0 : RayHitParam(w.ix, w.iy, w.b0, x3, y3, wx, wy);
  const double t1 = RayHitParam(w.ix, w.iy, w.b1, x3, y3, wx, wy);
  const double d2 = w.sigma + Hypot(len - w.ix, w.iy);
  if (t1 >= 1 && w.b1 >= len * (1 - kTinyWindowRel) &&
      d2 < dist_[mesh_.To(h)] * (1 - kFilterRelTol)) {
    UpdateVertex(mesh_.To(h), d2, id, h, w.ix, w.iy);
  }
  if (t1 > t0) {
    const double ux = wx / el, uy = wy / el;
    const double rx = w.ix - x3, ry = w.iy - y3;
    const double nix = rx * ux + ry * uy;
    const double niy = -rx * uy + ry * ux;
    if (t != kNoIndex) {
      MakeInterval(id, t, t0 * el, t1 * el, nix, niy, WindowSide::kRight, w.pseudo_source, w.sigma,
                   w.source);
    } else if (regions_ != nullptr) {
      ReachBoundary(e, t0 * el, t1 * el, nix, niy, w.sigma, w.source, w.pseudo_source);
    }
  }
}

// An interval window popped from the queue: (1) re-tested when over-filtering, (2) propagated
// across its face to the opposite vertex v3 (its distance; Lemma 1 decides which sides go on),
// (3) the straight-through bookkeeping at v3, (4) a child on each side that survives.
void IchSolver::ProcessInterval(uint32_t id, double popped_key) {
  Window w = pool_[id];  // copy: the pool may grow below
  const uint32_t generation = pool_.generation(id);
  if (keep_tree() && pool_.links(id).parent != kNoIndex) {
    // ReleaseIfDone below walks up to the parent; start fetching its links now.
    pool_.PrefetchLinks(pool_.links(id).parent);
  }
  const uint32_t h = w.element;
  if (options_.use_filter && epsilon_ > 0) {  // (1)
    const PopRetest retest = RetestOverFiltered(id, &w, popped_key);
    if (retest == PopRetest::kRequeued) return;
    if (retest == PopRetest::kDropped) {
      ++stats_.windows_filtered_at_pop;
      pool_.MarkProcessed(id);
      ReleaseIfDone(id);
      return;
    }
  }
  pool_.MarkProcessed(id);
  ++stats_.windows_processed;
  if (mesh_.FaceDegenerate(TriangleMesh::FaceOf(h))) {
    PassThroughDegenerate(id, w);
    ReleaseIfDone(id);
    return;
  }

  if (has_targets_ && face_target_head_[TriangleMesh::FaceOf(h)] != kNoIndex) {
    OfferWindowToTargets(h, w);
  }
  // (2) Across the face: where the ray from the image to the opposite vertex v3 crosses this
  // edge decides whether the window sees v3 and which sides have rays.
  Ahead ahead;
  ahead.len = mesh_.Length(h);
  ahead.x3 = mesh_.OppX(h);
  ahead.y3 = mesh_.OppY(h);
  ahead.v3 = mesh_.Opposite(h);
  ahead.cross_x = w.ix + (ahead.x3 - w.ix) * (-w.iy) / (ahead.y3 - w.iy);
  const double cover_tol = kCoverRelTol * ahead.len;
  ahead.sees_v3 = ahead.cross_x >= w.b0 - cover_tol && ahead.cross_x <= w.b1 + cover_tol;
  ahead.make_left = ahead.cross_x > w.b0 - cover_tol;  // some rays pass left of v3
  ahead.make_right = ahead.cross_x < w.b1 + cover_tol;
  ahead.v3_improved = false;
  if (ahead.sees_v3) {
    const double d3 = w.sigma + Hypot(ahead.x3 - w.ix, ahead.y3 - w.iy);
    ahead.v3_improved = UpdateVertex(ahead.v3, d3, id, h, w.ix, w.iy);
    if (options_.use_one_angle_one_split &&
        !OneAngleOneSplit(id, generation, h, d3, ahead.cross_x, cover_tol, &ahead.make_left,
                          &ahead.make_right)) {
      return;  // the paper's tree deleted this very window
    }
    RecordStraightThrough(w, h, ahead);  // (3)
  }
  if (ahead.make_left) MakeLeftChild(id, w, h, ahead);  // (4)
  if (ahead.make_right) MakeRightChild(id, w, h, ahead);
  ReleaseIfDone(id);
}

absl::Status IchSolver::Solve(const std::vector<ResolvedSource>& sources, DistanceField* out) {
  if (absl::Status s = Run(sources, nullptr, false, false, nullptr); !s.ok()) return s;
  if (std::isfinite(options_.max_distance)) {
    for (uint32_t v : workspace_->touched_vertices) {
      if (dist_[v] > options_.max_distance) {
        dist_[v] = kUnreachable;
        label_[v] = kNoIndex;
        origin_[v] = VertexOrigin{};
      }
    }
  }
  // The whole field is the answer: hand the arrays over (the workspace refills them next time).
  out->internal_distance = std::move(dist_);
  out->internal_source = std::move(label_);
  out->internal_origin = std::move(origin_);
  out->stats = stats_;
  return absl::OkStatus();
}

absl::Status IchSolver::SolveForTargets(const std::vector<ResolvedSource>& sources,
                                        const std::vector<ResolvedTarget>& targets,
                                        bool use_heuristic, bool stop_early,
                                        std::vector<TargetResult>* results, SolveStats* stats) {
  absl::Status status = Run(sources, &targets, use_heuristic, stop_early, results);
  if (stats != nullptr) *stats = stats_;
  if (!status.ok()) return status;
  for (uint32_t t = 0; t < targets.size(); ++t) {
    TargetResult& r = (*results)[t];
    if (r.distance > options_.max_distance) r = TargetResult{};
    for (uint32_t v : targets[t].vertices) {
      if (dist_[v] < r.distance && dist_[v] <= options_.max_distance) {
        r.distance = dist_[v];
        r.label = label_[v];
        r.vertex = v;
      }
    }
  }
  return absl::OkStatus();
}

absl::Status IchSolver::Run(const std::vector<ResolvedSource>& sources,
                            const std::vector<ResolvedTarget>* targets, bool use_heuristic,
                            bool stop_early, std::vector<TargetResult>* results) {
  const auto start = std::chrono::steady_clock::now();
  stats_ = SolveStats{};
  has_targets_ = targets != nullptr;
  refit_goal_ = false;
  if (has_targets_) {
    targets_ = targets;
    target_results_ = results;
    results->assign(targets->size(), TargetResult{});
    stop_early_ = stop_early;
    unfinished_.clear();
    for (uint32_t t = 0; t < targets->size(); ++t) unfinished_.push_back(t);
    heuristic_ = use_heuristic && regions_ == nullptr && FitGoal();
    // Refitting needs the stop test's bookkeeping (TargetsBound), hence stop_early.
    refit_goal_ = use_heuristic && regions_ == nullptr && stop_early && targets->size() > 1;
    next_final_ = kUnreachable;
    for (uint32_t t = 0; t < targets->size(); ++t) {
      for (uint32_t v : (*targets)[t].vertices) {
        vertex_is_target_[v] = 1;
        workspace_->target_vertices.push_back(v);
      }
      for (uint32_t k = 0; k < (*targets)[t].placements.size(); ++k) {
        const uint32_t f = (*targets)[t].placements[k].face;
        if (face_target_head_[f] == kNoIndex) workspace_->target_faces.push_back(f);
        face_target_entry_.push_back({t, k});
        face_target_next_.push_back(face_target_head_[f]);
        face_target_head_[f] = static_cast<uint32_t>(face_target_entry_.size() - 1);
      }
    }
    targets_dirty_ = true;
  }
  const uint32_t nv = mesh_.vertex_count();
  const bool has_points = regions_ != nullptr && regions_->point_count() > 0;
  queue_.Reset((has_points ? kRegionQueueResolutionEdges : kQueueResolutionEdges) *
               mesh_.MeanEdgeLength());
  queue_.reserve(4 * size_t{nv});
  if (regions_ != nullptr) {
    if (regions_->point_count() >= kPointEntry) {
      return LimitExceededError(
          Limit::kSteinerPoints,
          absl::StrFormat("%d boundary points, more than a solve can queue (%d)",
                          regions_->point_count(), kPointEntry - 1));
    }
    point_cost_.assign(regions_->point_count(), kUnreachable);
    point_origin_.assign(regions_->point_count(), VertexOrigin{});
    point_source_.assign(regions_->point_count(), kNoIndex);
    point_slot_.assign(regions_->point_count(), kNoSlot);
    point_seq_.assign(regions_->point_count(), 0);
    block_max_.assign((regions_->point_count() + kPointBlock - 1) / kPointBlock, kUnreachable);
  }

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
    // A boundary point (regions only: no window id reaches kPointEntry, see below).
    const bool is_point = regions_ != nullptr && e.window >= kPointEntry;
    if (is_point) {
      const uint32_t p = e.window - kPointEntry;
      if (e.generation != point_seq_[p] || point_slot_[p] == kNoSlot) continue;  // superseded
    } else {
      // The next window is most likely the new top: fetch it while this one is processed.
      if (const QueueEntry* next = queue_.Peek(); next != nullptr && next->window < kPointEntry) {
        pool_.Prefetch(next->window);
      }
      // Only the paper's tree deletes queued windows (Lemma 1's subtrees); without it every
      // entry is a live queued window, and its links are not even read.
      if (pool_.IsStale(e.window, e.generation)) {
        continue;  // deleted (Lemma 1) or recycled since it was queued
      }
    }
    // Every queued key is at least LowerBound() (entries of near-equal keys pop in any order).
    const double floor = queue_.LowerBound();
    if (floor > options_.max_distance) break;
    // Every path not yet accounted for is at least as long as this key (keys are lower bounds,
    // and never decrease along a path): targets whose distance is at most the key are final.
    if (target_results_ != nullptr && stop_early_ && floor >= TargetsBound()) break;
    if (refit_goal_ && floor >= next_final_) RefitGoal(floor);
    if (++polls == kCancelPollInterval) {
      polls = 0;
      if (options_.cancel != nullptr && options_.cancel->IsCancelled()) {
        status = absl::CancelledError("geodesic solve cancelled");
        break;
      }
      // Window ids must stay below the boundary points' tag (a poll interval makes far fewer
      // windows than the margin).
      if (regions_ != nullptr && pool_.ids_issued() >= kPointEntry / 2) {
        status = LimitExceededError(
            Limit::kWindows,
            absl::StrFormat("%d windows made, more than a solve on regions can index; use "
                            "max_windows or a max_distance",
                            pool_.ids_issued()));
        break;
      }
    }
    if (options_.max_windows != 0 && stats_.windows_created > options_.max_windows) {
      // lambda is suggested only where it applies: a travel solve (on regions) refuses it.
      status = LimitExceededError(
          Limit::kWindows,
          absl::StrFormat(
              "window budget exceeded: %d windows created (limit %d); use a larger budget%s",
              stats_.windows_created, options_.max_windows,
              regions_ != nullptr ? " or a max_distance" : ", a max_distance, or lambda > 0"));
      break;
    }
    if (is_point) {
      ProcessBoundaryPoint(e.window - kPointEntry);
      continue;
    }
    const WindowKind kind = pool_[e.window].kind;
    if (kind == WindowKind::kPseudoSource) {
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
  stats_.solve_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return status;
}

}  // namespace geodex::ich
