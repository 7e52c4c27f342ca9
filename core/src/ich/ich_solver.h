#pragma once

// The improved Chen-Han engine (Xin & Wang 2009; applications in Xin & Wang 2010). Private to core:
// callers use ComputeDistanceField (geodex/geodesic_solver.h).

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/triangle_mesh.h"
#include "ich/region_links.h"
#include "ich/solve_workspace.h"
#include "ich/window.h"

namespace geodex::ich {

// A source resolved to internal ids: a vertex, or a point inside (or on the border of) a
// non-degenerate face given in the frame of the face's half-edge 3*face (corner 0 at the origin,
// corner 1 on the +x axis).
struct ResolvedSource {
  bool is_vertex = true;
  uint32_t vertex = kNoIndex;
  uint32_t face = kNoIndex;
  double px = 0, py = 0;
  uint32_t label = 0;
};

// A point the solve must answer exactly (single-target queries, matrices, exact point distances):
// a vertex (all its internal copies), or a point placed in the non-degenerate faces that contain
// it (an edge point lies in every face of its edge), in the frame of half-edge 3*face.
struct ResolvedTarget {
  struct Placement {
    uint32_t face;
    double px, py;
  };
  std::vector<uint32_t> vertices;
  std::vector<Placement> placements;
  double position[3] = {0, 0, 0};  // internal (recentred) 3D coordinates, for the heuristic
};

// What the solve found for a target. A face-point target is reached straight from the image of
// `origin` (in the frame of origin.half_edge, where the target sits at (tx, ty)), or straight
// from vertex origin.pseudo_source when origin.half_edge == kNoIndex. A vertex target's path
// starts at `vertex` and follows the per-vertex origins.
struct TargetResult {
  double distance = kUnreachable;
  uint32_t label = kNoIndex;
  uint32_t vertex = kNoIndex;  // vertex targets: the internal copy that is nearest
  VertexOrigin origin;
  double tx = 0, ty = 0;
  uint32_t face = kNoIndex;  // face-point targets: the placement used, for the start position
  double px = 0, py = 0;
};

class IchSolver {
 public:
  // Windows whose smallest distance exceeds `key_cap` (or options.max_distance) are never made:
  // callers that switch the filter off pass an upper bound of every distance here.
  IchSolver(const TriangleMesh& mesh, const GeodesicOptions& options,
            double key_cap = std::numeric_limits<double>::infinity());
  // Gives the workspace back to the mesh, restoring only what the solve touched.
  ~IchSolver();
  IchSolver(const IchSolver&) = delete;
  IchSolver& operator=(const IchSolver&) = delete;

  // Fills out->internal_distance/_source/_origin and out->stats.
  absl::Status Solve(const std::vector<ResolvedSource>& sources, DistanceField* out);

  // Answers `targets` exactly, stopping as soon as every target's distance is final (with
  // `stop_early`). With `use_heuristic` (one target only) windows are ordered by the paper's
  // section 5 key, sigma + min over the interval of (|I p| + |p t|), which never exceeds the
  // length of a path through the window. Only the targets' results are meaningful then, not the
  // whole field. The per-vertex arrays stay in the workspace (read them with the accessors below
  // until the solver goes): no O(V) copy, and `stats` (if given) receives the counters.
  absl::Status SolveForTargets(const std::vector<ResolvedSource>& sources,
                               const std::vector<ResolvedTarget>& targets, bool use_heuristic,
                               bool stop_early, std::vector<TargetResult>* results,
                               SolveStats* stats);

  // With k > 0, a targeted solve with stop_early stops once the k nearest targets are final (the
  // other targets' results are then upper bounds, or +inf).
  void set_final_needed(uint32_t k) { final_needed_ = k; }

  // Runs on the union of a weighted surface's regions (weighted_regions.h): vertex copies share
  // their cost and boundary points pass theirs on to both regions. `links` must outlive the
  // solver; the solver then uses no A* key (costs in different regions are not comparable by
  // position) and the paper's tree is not supported (Method::kExact only).
  void set_regions(const RegionLinks* links) { regions_ = links; }
  // Per boundary point of the last solve on regions: where its cost came from (ReachPoint), for
  // tracing paths back through the points.
  const std::vector<VertexOrigin>& point_origins() const { return point_origin_; }

  // The last solve's per-vertex arrays (internal ids), for backtracing paths.
  const std::vector<double>& distances() const { return dist_; }
  const std::vector<uint32_t>& labels() const { return label_; }
  const std::vector<VertexOrigin>& origins() const { return origin_; }

 private:
  absl::Status Run(const std::vector<ResolvedSource>& sources,
                   const std::vector<ResolvedTarget>* targets, bool use_heuristic, bool stop_early,
                   std::vector<TargetResult>* results);
  void TouchVertex(uint32_t v) { workspace_->touched_vertices.push_back(v); }
  void SeedVertex(uint32_t v, uint32_t label);
  // A pseudo-source window at `vertex` (kNoIndex: a source point's root), not yet queued.
  uint32_t NewPseudoSourceWindow(uint32_t vertex, double sigma, uint32_t source, uint32_t level) {
    return NewPointWindow(WindowKind::kPseudoSource, vertex, vertex, sigma, source, level);
  }
  // A window emitting from one point (`element`: a vertex, or a boundary point), not yet queued.
  uint32_t NewPointWindow(WindowKind kind, uint32_t element, uint32_t pseudo_source, double sigma,
                          uint32_t source, uint32_t level);
  // Sets vertex v's distance, label and origin (d below its distance): the one place a vertex's
  // state changes after seeding.
  void SetVertex(uint32_t v, double d, uint32_t source, const VertexOrigin& origin) {
    if (dist_[v] == kUnreachable) TouchVertex(v);
    dist_[v] = d;
    straight_through_[v] = 0;
    if (has_targets_ && vertex_is_target_[v]) targets_dirty_ = true;
    label_[v] = source;
    origin_[v] = origin;
  }
  void SeedFacePoint(const ResolvedSource& s);
  void ProcessPseudoSource(uint32_t id);
  void ProcessInterval(uint32_t id, double popped_key);
  // ProcessInterval's named steps (ich_solver.cc; docs/engine.md).
  enum class PopRetest : uint8_t { kKeep, kDropped, kRequeued };
  PopRetest RetestOverFiltered(uint32_t id, Window* w, double popped_key);
  // What a window sees across its face: the opposite vertex v3 (its position in the edge's frame,
  // whether the window's rays reach it, whether its distance improved) and the sides on which
  // rays pass v3, where children go.
  struct Ahead {
    double len, x3, y3, cross_x;
    uint32_t v3;
    bool sees_v3, make_left, make_right, v3_improved;
  };
  void RecordStraightThrough(const Window& w, uint32_t h, const Ahead& ahead);
  void MakeLeftChild(uint32_t id, const Window& w, uint32_t h, const Ahead& ahead);
  void MakeRightChild(uint32_t id, const Window& w, uint32_t h, const Ahead& ahead);
  void PassThroughDegenerate(uint32_t id, const Window& w);
  void EmitAcrossDegenerate(uint32_t id, uint32_t corner, double sigma, uint32_t source);
  // Straight distances to a face's vertices and windows through its edges, from a point given in
  // the frame of half-edge `frame_edge` of that face.
  void EmitFromPointInFace(uint32_t parent, uint32_t frame_edge, double px, double py, double sigma,
                           uint32_t pseudo_source, uint32_t source);
  // Windows of a saddle whose best path runs straight through it: only its shadow sector.
  void SpawnShadowWindows(uint32_t id, uint32_t v, double sigma, uint32_t source);
  static double IntervalKey(double b0, double b1, double ix, double iy, double sigma);
  // Cuts off the parts of [b0, b1] better reached straight from the edge's endpoints (the filter
  // theorem, point by point). Returns false when nothing is left.
  // *ra, *rb receive |I b0| and |I b1| of the trimmed interval (for IsFiltered and the key).
  bool TrimByEndpoints(uint32_t half_edge, double* b0, double* b1, double ix, double iy,
                       double sigma, double* ra, double* rb) const;

  // Lemma 1 for a window `id` on half-edge h that sees the opposite vertex at distance d3, its ray
  // crossing the edge at cross_x: clears *make_left or *make_right for a loser; records a winner
  // (with the tree, deleting the old winner's doomed subtree). False when that deleted `id` itself.
  bool OneAngleOneSplit(uint32_t id, uint32_t generation, uint32_t h, double d3, double cross_x,
                        double cover_tol, bool* make_left, bool* make_right);
  // Lower a vertex's distance if `d` is smaller; spawns a pseudo-source window where paths may
  // bend.
  bool UpdateVertex(uint32_t v, double d, uint32_t parent, uint32_t half_edge, double ix,
                    double iy);
  // Creates an interval window on `half_edge` (propagating into its face) unless Lemma 2 or size
  // rules drop it.
  void MakeInterval(uint32_t parent, uint32_t half_edge, double b0, double b1, double ix, double iy,
                    WindowSide side, uint32_t pseudo_source, double sigma, uint32_t source);
  // Lemma 2 (filter theorem): true when no point of the window's interval can be reached more
  // cheaply through it than straight from one of the three vertices of the face it came through.
  // ra, rb: |I b0| and |I b1|.
  bool IsFiltered(uint32_t half_edge, double b0, double b1, double ix, double iy, double sigma,
                  double ra, double rb, WindowSide side, double epsilon) const;
  void Push(uint32_t id, double key);
  // Removes `id`'s subtree (pseudo-source windows are kept and become roots), then frees any
  // processed ancestor left without children.
  void DeleteSubtree(uint32_t id);
  // Frees a processed window (with the tree: once its subtree is gone, walking up).
  void ReleaseIfDone(uint32_t id);
  void RelaxNeighbors(uint32_t v, double d, uint32_t source);

  // --- regions (region_links.h) ---
  // A window's rays meeting the boundary half-edge e over [x0, x1] (measured from e's end, the
  // image at (ix, iy) as MakeInterval takes it on e's twin): the chain's points there get costs.
  // `pseudo_source`: the window's (what a path from these points bends at next).
  void ReachBoundary(uint32_t e, double x0, double x1, double ix, double iy, double sigma,
                     uint32_t source, uint32_t pseudo_source);
  // Lowers boundary point p's cost to d; `origin` says from where: a window across the face of
  // boundary half-edge `origin.half_edge` (its image in that half-edge's frame, its
  // pseudo-source), or (half_edge kNoIndex) along the chain from the vertex or the (tagged) point
  // `origin.pseudo_source`.
  void ReachPoint(uint32_t p, double d, uint32_t source, const VertexOrigin& origin);
  void ProcessBoundaryPoint(uint32_t p);
  // A copy of v got cost d: its other copies get it too, and spawn their own windows.
  void ShareWithCopies(uint32_t v, double d, uint32_t source);
  // From boundary vertex v along each boundary edge at it, to the chain's point nearest v.
  void RelaxChainEnds(uint32_t v, double d, uint32_t source);

  // --- targets ---
  // The queue key of an interval window: its smallest distance, plus the A* term when enabled.
  double WindowKey(uint32_t half_edge, double b0, double b1, double ix, double iy, double sigma,
                   double plain_key) const;
  double VertexKey(uint32_t v, double d) const;
  // The A* goal: the target, or a ball around the targets not yet final (unfinished_). False when
  // the ball is too large to help.
  bool FitGoal();
  // Drops the targets final at queue floor `floor` from the goal and fits the ball again around
  // the rest (a matrix row's far targets steer the search once its near ones are done).
  void RefitGoal(double floor);
  double CurrentTargetDistance(uint32_t t) const;  // the best distance found for target t so far
  // Offers target candidates from a window entering face(h), and from a point (a pseudo-source
  // vertex, or a source point) seen straight inside face f.
  void OfferWindowToTargets(uint32_t h, const Window& w);
  void OfferPointToTargets(uint32_t f, double px, double py, double d, uint32_t label,
                           uint32_t via_vertex, uint32_t frame_edge, double fx, double fy);
  void Offer(uint32_t t, uint32_t placement, double d, uint32_t label, const VertexOrigin& origin,
             double tx, double ty);
  // The largest current target distance (+inf while any is unknown); also updates next_final_.
  double TargetsBound();

  // First: the references below point into it. From the mesh's cache (or owned, for a mesh that
  // has none).
  std::unique_ptr<SolveWorkspace> workspace_;
  const TriangleMesh& mesh_;
  const GeodesicOptions& options_;
  double key_cap_;
  double epsilon_ = 0;  // over-filtering margin lambda * L (section 7)

  const std::vector<ResolvedTarget>* targets_ = nullptr;
  std::vector<TargetResult>* target_results_ = nullptr;
  bool heuristic_ = false;
  bool stop_early_ = false;
  bool targets_dirty_ = true;
  double targets_bound_ = kUnreachable;
  bool has_targets_ = false;
  double goal_[3] = {0, 0, 0};  // A*: the target, or the centre of a ball holding the targets
  double goal_radius_ = 0;
  // Several targets with A*: the ones not yet final, and the smallest current distance among them
  // (once the queue's floor passes it, that target is final and the goal is refitted).
  bool refit_goal_ = false;
  std::vector<uint32_t> unfinished_;
  double next_final_ = kUnreachable;
  uint32_t final_needed_ = 0;          // 0: every target
  std::vector<double> bound_scratch_;  // TargetsBound's k-th smallest, k < targets

  // The workspace's arrays under the names the rules use (see SolveWorkspace).
  std::vector<uint32_t>& face_target_head_;
  std::vector<uint32_t>& face_target_next_;
  std::vector<std::pair<uint32_t, uint32_t>>& face_target_entry_;
  std::vector<uint8_t>& vertex_is_target_;
  std::vector<double>& dist_;
  std::vector<uint32_t>& label_;
  std::vector<VertexOrigin>& origin_;
  std::vector<uint8_t>& straight_through_;
  HugeVector<SplitRecord>& split_;       // Lemma 1, per half-edge
  HugeVector<SplitOwner>& split_owner_;  // Lemma 1's winners, the paper's tree only
  // The paper's window tree (Method::kIch) is the pool's links: children are linked to their
  // parents so Lemma 1 can delete an old winner's subtree. Without them (Method::kExact) a window
  // is freed as soon as it is processed and Lemma 1 prunes forward only.
  WindowPool& pool_;
  bool keep_tree() const { return pool_.with_links(); }
  WindowQueue& queue_;
  std::vector<uint32_t>& scratch_;  // reused stack for subtree deletion
  SolveStats stats_;

  const RegionLinks* regions_ = nullptr;
  std::vector<double> point_cost_;          // per boundary point
  std::vector<VertexOrigin> point_origin_;  // where its cost came from (ReachPoint)
  std::vector<uint32_t> point_source_;      // the label of its cost
  // A boundary point is queued as itself, not as a window (queue entries name it as
  // kPointEntry | p): at most one live entry per point, the one numbered point_seq_[p], in queue
  // slot point_slot_[p] (kNoSlot: none). A cost that drops within that slot needs no new entry,
  // and a window is made only when the point is processed.
  static constexpr uint32_t kPointEntry = 1u << 31;
  static constexpr uint64_t kNoSlot = ~uint64_t{0};
  std::vector<uint64_t> point_slot_;
  std::vector<uint32_t> point_seq_;
  // The largest point_cost_ of each run of kPointBlock boundary points (by index): a window whose
  // least cost over a run's stretch of its edge is no less prices none of its points
  // (ReachBoundary skips the run without a square root per point).
  static constexpr uint32_t kPointBlock = 16;
  std::vector<double> block_max_;
};

}  // namespace geodex::ich
