#pragma once

// The improved Chen-Han engine (Xin & Wang 2009; applications in Xin & Wang 2010). Private to core:
// callers use ComputeDistanceField (geodex/geodesic_solver.h).

#include <cstdint>
#include <limits>
#include <vector>

#include "absl/status/status.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/triangle_mesh.h"
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

class IchSolver {
 public:
  // Windows whose smallest distance exceeds `key_cap` (or options.max_distance) are never made:
  // callers that switch the filter off pass an upper bound of every distance here.
  IchSolver(const TriangleMesh& mesh, const GeodesicOptions& options,
            double key_cap = std::numeric_limits<double>::infinity());

  // Fills out->internal_distance/_source/_origin and out->stats.
  absl::Status Solve(const std::vector<ResolvedSource>& sources, DistanceField* out);

 private:
  void SeedVertex(uint32_t v, uint32_t label);
  void SeedFacePoint(const ResolvedSource& s);
  void ProcessPseudoSource(uint32_t id);
  void ProcessInterval(uint32_t id, double popped_key);
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
  bool TrimByEndpoints(uint32_t half_edge, double* b0, double* b1, double ix, double iy,
                       double sigma) const;

  // Lower a vertex's distance if `d` is smaller; spawns a pseudo-source window where paths may bend.
  bool UpdateVertex(uint32_t v, double d, uint32_t parent, uint32_t half_edge, double ix, double iy);
  // Creates an interval window on `half_edge` (propagating into its face) unless Lemma 2 or size
  // rules drop it.
  void MakeInterval(uint32_t parent, uint32_t half_edge, double b0, double b1, double ix, double iy,
                    WindowSide side, uint32_t pseudo_source, double sigma, uint32_t source);
  // Lemma 2 (filter theorem): true when no point of the window's interval can be reached more
  // cheaply through it than straight from one of the three vertices of the face it came through.
  bool IsFiltered(uint32_t half_edge, double b0, double b1, double ix, double iy, double sigma,
                  WindowSide side, double epsilon) const;
  void Push(uint32_t id, double key);
  // Removes `id`'s subtree (pseudo-source windows are kept and become roots), then frees any
  // processed ancestor left without children.
  void DeleteSubtree(uint32_t id);
  void ReleaseIfDone(uint32_t id);
  void RelaxNeighbors(uint32_t v, double d, uint32_t source);

  const TriangleMesh& mesh_;
  const GeodesicOptions& options_;
  double key_cap_;
  double epsilon_ = 0;  // over-filtering margin lambda * L (section 7)

  std::vector<double> dist_;
  std::vector<uint32_t> label_;
  std::vector<VertexOrigin> origin_;
  std::vector<uint8_t> straight_through_;  // see ProcessInterval
  std::vector<SplitOwner> owner_;
  WindowPool pool_;
  WindowQueue queue_;
  std::vector<uint32_t> scratch_;  // reused stack for subtree deletion
  SolveStats stats_;
};

}  // namespace geodex::ich
