// The weighted engine's graph (private to core; geodex/weighted_field.h is the engine's API): the
// Steiner points on a mesh's edges with the faces' and edges' weights (SteinerGraph, placed in
// steiner_graph.cc), and sources and targets resolved onto the mesh (Located, located_points.cc).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"

namespace geodex::weighted_internal {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kHalfPi = 1.5707963267948966;
// Parent markers of nodes seeded by a source: the node is a source vertex, or it is reached by
// one straight segment from a source point.
inline constexpr uint32_t kFromSourceVertex = kNoIndex - 1;
inline constexpr uint32_t kFromSourcePoint = kNoIndex - 2;
inline constexpr uint32_t kMaxNodes = kNoIndex - 3;

using Vec = std::array<double, 3>;

inline double Dist(const Vec& a, const Vec& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// A source or target resolved onto the mesh.
struct Located {
  SurfacePoint canonical;
  Vec pos{};                         // internal (recentred) coordinates
  std::vector<uint32_t> vertices;    // kVertex: the internal copies
  std::vector<uint32_t> half_edges;  // kEdge: one per face on the edge
  uint32_t face = kNoIndex;          // kFace
};

// The Steiner points (positions along the edges) and the per-face/per-edge weights. Node ids:
// internal vertices 0..nv-1, then the Steiner points of edge e at nv + first[e] .. nv +
// first[e+1] - 1 in order of increasing parameter along the edge's canonical half-edge.
class SteinerGraph {
 public:
  SteinerGraph(const TriangleMesh& mesh, const WeightedOptions& options)
      : mesh_(mesh), weights_(options.face_weight), nv_(mesh.vertex_count()) {}

  // Bounded: the geometric placement of Aleksandrov, Maheshwari and Sack (dense near vertices),
  // for a (1 + epsilon) bound on link paths. Uniform: ceil(1 / epsilon) - 1 points evenly spaced
  // on every edge (spacing epsilon x its length), for a search that crosses between nodes
  // (Search::CrossSegments) and claims no bound: the error then falls about as the spacing
  // squared, so far fewer points reach a given accuracy. Uniform placement is graded near
  // `seeds` (the positions searches will start from, when known; GradedCount).
  // The bounded placement is also refined around `anchors`, the points strictly inside faces or
  // edges that searches will start or end at (AddAnchorPoints): without it, two such points close
  // together across an edge may cost many times their true least cost.
  enum class Placement { kBounded, kUniform };
  absl::Status Build(double epsilon, uint64_t max_points, Placement placement,
                     const std::vector<Vec>& seeds, const std::vector<Located>& anchors);
  // Before Build: points only on the edges whose half-edge edge_half (the one of the lower id)
  // is marked, placed exactly as on the whole graph (the regions' boundaries, weighted_regions.h).
  void PlaceOnlyOn(std::vector<uint8_t> marked_half) { only_half_ = std::move(marked_half); }
  bool Placed(uint32_t e) const { return only_half_.empty() || only_half_[edge_half_[e]]; }

  const TriangleMesh& mesh() const { return mesh_; }
  uint32_t nv() const { return nv_; }
  uint64_t steiner_points() const { return param_.size(); }
  uint64_t graph_edges() const { return graph_edges_; }
  uint32_t edge_count() const { return static_cast<uint32_t>(edge_half_.size()); }
  uint32_t node_count() const { return nv_ + static_cast<uint32_t>(param_.size()); }
  double FaceWeight(uint32_t f) const { return weights_.empty() ? 1.0 : weights_[f]; }
  uint32_t EdgeOfHalf(uint32_t h) const { return edge_of_half_[h]; }
  uint32_t EdgeHalf(uint32_t e) const { return edge_half_[e]; }
  double EdgeWeight(uint32_t e) const { return edge_weight_[e]; }
  uint32_t First(uint32_t e) const { return nv_ + first_[e]; }  // first Steiner node of e
  uint32_t End(uint32_t e) const { return nv_ + first_[e + 1]; }
  // The edge of a Steiner node.
  uint32_t EdgeOfNode(uint32_t node) const {
    const uint32_t i = node - nv_;
    return static_cast<uint32_t>(std::upper_bound(first_.begin(), first_.end(), i) -
                                 first_.begin()) -
           1;
  }
  double Param(uint32_t node) const { return param_[node - nv_]; }
  const double* Params(uint32_t node) const { return param_.data() + (node - nv_); }
  Vec Pos(uint32_t node) const {
    if (node < nv_) return mesh_.Position(node);
    return PosOn(node, EdgeOfNode(node));
  }
  // The position of Steiner node `node` of edge e.
  Vec PosOn(uint32_t node, uint32_t e) const {
    const uint32_t h = edge_half_[e];
    return Lerp(mesh_.Position(mesh_.From(h)), mesh_.Position(mesh_.To(h)), Param(node));
  }
  static Vec Lerp(const Vec& a, const Vec& b, double s) {
    return {a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])};
  }
  uint64_t bytes() const {
    return param_.capacity() * sizeof(double) +
           (first_.capacity() + edge_half_.capacity() + edge_of_half_.capacity()) *
               sizeof(uint32_t) +
           edge_weight_.capacity() * sizeof(double);
  }

 private:
  // The uniform placement's points on an edge of length `len` whose midpoint lies `reach` from
  // the nearest seed: `uniform` far away, up to kMostDense times as many within a few edge
  // lengths. Near a source the times are small, so an absolute error that is small elsewhere is a
  // large relative one there: the times bend most there (a cone around a point source) and the
  // crossings' error, about the spacing squared, adds up from the source outward. A spacing that
  // shrinks as the distance to the seed (down to 1 / kMostDense of the even one, within
  // kReach / kMostDense edge lengths) keeps that error a near-constant share of the time, for few
  // extra points: some 30k per seed on Jacksboro at any resolution (at --dem-step 2, 4% more, and
  // a Tobler field's largest error 1.2% -> 0.5% of the time).
  static constexpr double kReach = 20;     // edge lengths: beyond, the even spacing
  static constexpr double kMostDense = 4;  // the densest points, times the even count
  static constexpr size_t kMaxSeeds = 64;  // more seeds: no grading (the search per seed of a
                                           // large matrix would pay for every other one's disc)
  static uint32_t GradedCount(uint32_t uniform, double len, double reach) {
    const double times = std::clamp(kReach * len / std::max(reach, 1e-300), 1.0, kMostDense);
    return static_cast<uint32_t>(std::ceil((uniform + 1) * times)) - 1;
  }

  // The anchors' extra points, as (edge, parameter) pairs (Build's bounded placement): the feet's
  // progressions into *extra, the corners' wanted continuations below r(v) into *reach_down as
  // (vertex, down to), which AddVicinityPoints places.
  void AddAnchorPoints(const Located& q, double epsilon, const std::vector<double>& lambda,
                       const std::vector<double>& radius, const std::vector<double>& w_ratio,
                       std::vector<std::pair<uint32_t, double>>* extra,
                       std::vector<std::pair<uint32_t, double>>* reach_down, uint64_t* room) const;
  void AddVicinityPoints(std::vector<std::pair<uint32_t, double>> reach_down,
                         const std::vector<double>& lambda, const std::vector<double>& radius,
                         std::vector<std::pair<uint32_t, double>>* extra, uint64_t* room) const;
  // Takes the n points of the progression from `from` by `factor` up to `to` (on each of `sides`
  // sides) out of *room; false (and *room 0) when they do not fit (a factor next to 1 under a tiny
  // epsilon), so no loop runs for ever or fills memory before the Steiner-point limit is checked.
  static bool Fits(double from, double factor, double to, uint64_t* room, int sides = 1) {
    if (!(from < to)) return true;
    const double n = sides * (std::ceil(std::log(to / from) / std::log(factor)) + 1);
    if (!(n <= static_cast<double>(*room))) {
      *room = 0;
      return false;
    }
    *room -= static_cast<uint64_t>(n);
    return true;
  }

  // Number of i >= 0 with r lambda^i < half.
  static uint32_t SideCount(double r, double lambda, double half) {
    if (!(r < half)) return 0;
    double n = std::floor(std::log(half / r) / std::log(lambda)) + 1;
    n = std::min(n, 1e9);  // the limits below stop such meshes (near-zero angles)
    uint32_t k = static_cast<uint32_t>(n);
    while (k > 0 && r * std::pow(lambda, k - 1) >= half) --k;
    while (k < 1000000000u && r * std::pow(lambda, k) < half) ++k;
    return k;
  }

  // Merges the anchors' (edge, parameter) points into the chains, each kept strictly increasing.
  void MergeExtraPoints(std::vector<std::pair<uint32_t, double>> extra);

  const TriangleMesh& mesh_;
  const std::vector<double>& weights_;
  uint32_t nv_;
  std::vector<uint32_t> edge_of_half_, edge_half_, first_;
  std::vector<double> edge_weight_, param_;
  std::vector<uint8_t> only_half_;
  uint64_t graph_edges_ = 0;
};

// located_points.cc

absl::StatusOr<Located> Locate(const TriangleMesh& mesh, const SurfacePoint& p);
// Resolves the points (errors name the point as given).
absl::Status Prepare(const TriangleMesh& mesh, const std::vector<SurfacePoint>& points,
                     std::vector<Located>* located);
// A graph node, and a located point, as a path's point (file coordinates).
PathPoint NodePoint(const SteinerGraph& g, uint32_t n);
PathPoint LocatedPoint(const TriangleMesh& mesh, const Located& l);

}  // namespace geodex::weighted_internal
