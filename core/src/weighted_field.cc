#include "geodex/weighted_field.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define GEODEX_AVX2_FILTER 1  // MarkCandidatesAvx2, chosen at run time
#endif

#include "absl/strings/str_format.h"
#include "geodex/geodesic_solver.h"
#include "geodex/limits.h"
#include "mesh_lookup.h"
#include "weighted_regions.h"

namespace geodex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kHalfPi = 1.5707963267948966;
// Parent markers of nodes seeded by a source: the node is a source vertex, or it is reached by
// one straight segment from a source point.
constexpr uint32_t kFromSourceVertex = kNoIndex - 1;
constexpr uint32_t kFromSourcePoint = kNoIndex - 2;
constexpr uint32_t kMaxNodes = kNoIndex - 3;

using Vec = std::array<double, 3>;

double Dist(const Vec& a, const Vec& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// An allocator that leaves elements default-initialised: a vector of doubles resized with it is
// not written, so its pages are only mapped where a search writes them (Search's headed state).
template <typename T>
struct UninitializedAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <typename U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <typename T>
using LazyVector = std::vector<T, UninitializedAllocator<T>>;

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

// The bound's argument (weighted_field.h) needs every stretch of an optimal path near a vertex to
// lie between two long pieces inside the vertex's star, and every crossing of an edge to have
// pieces at least t sin(theta) long on both sides. A path starting at a point q strictly inside a
// face or an edge has neither near q: q may lie a hair from an edge, or inside a vertex's vicinity
// ball, where no node lies (Aleksandrov, Maheshwari and Sack make such points vertices). So, for
// each face holding q:
//  * on each of its edges (not q's own): q's foot and points sqrt(epsilon / 2) h mu^i away from it
//    on both sides (h: q's distance to the edge's line, mu = 1 + sqrt(epsilon / 2)) until that
//    distance reaches where the edge's own points are as dense (L / 2 x sin theta): a crossing x
//    at distance rho from the foot has a node within sqrt(epsilon / 8) rho <= sqrt(epsilon / 8)
//    |q x| of it, the spacing the argument gives a piece |q x| long;
//  * on each edge at each of its corners v: v's progression r lambda^i continued below r(v), from
//    r'(v) = (epsilon / 8) |q v| w_min(v) / w_max(v): a stretch rerouted through v then lies in a
//    ball small against the piece from q to it, as r(v) is against d(v).
// Both stop at 1e-9 of their scale (a point closer than that to an edge or vertex is on it, for
// the bound). Extra points per anchor: some hundreds (logarithmic in how close q lies).
void SteinerGraph::AddAnchorPoints(const Located& q, double epsilon,
                                   const std::vector<double>& lambda,
                                   const std::vector<double>& radius,
                                   const std::vector<double>& w_ratio,
                                   std::vector<std::pair<uint32_t, double>>* extra,
                                   std::vector<std::pair<uint32_t, double>>* reach_down,
                                   uint64_t* room) const {
  std::vector<uint32_t> faces;
  uint32_t own_edge = kNoIndex;
  if (q.canonical.kind == SurfacePoint::Kind::kFace) faces.push_back(q.face);
  if (q.canonical.kind == SurfacePoint::Kind::kEdge) {
    for (const uint32_t h : q.half_edges) faces.push_back(TriangleMesh::FaceOf(h));
    own_edge = edge_of_half_[q.half_edges[0]];
  }
  const double root = std::sqrt(epsilon / 2);
  const double mu = 1 + root;
  for (const uint32_t f : faces) {
    if (!std::isfinite(FaceWeight(f)) || mesh_.FaceDegenerate(f)) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t e = edge_of_half_[3 * f + k];
      if (e == own_edge || lambda[e] == 0) continue;
      const uint32_t h0 = edge_half_[e];
      const Vec a = mesh_.Position(mesh_.From(h0)), b = mesh_.Position(mesh_.To(h0));
      const double len = mesh_.Length(h0);
      const Vec u = {(b[0] - a[0]) / len, (b[1] - a[1]) / len, (b[2] - a[2]) / len};
      const Vec aq = {q.pos[0] - a[0], q.pos[1] - a[1], q.pos[2] - a[2]};
      const double along = aq[0] * u[0] + aq[1] * u[1] + aq[2] * u[2];
      const Vec off = {aq[0] - along * u[0], aq[1] - along * u[1], aq[2] - along * u[2]};
      const double height = std::sqrt(off[0] * off[0] + off[1] * off[1] + off[2] * off[2]);
      const double foot = std::clamp(along, 0.0, len);
      if (foot > 0 && foot < len) extra->push_back({e, foot / len});
      const double reach = len / 2 * (lambda[e] - 1) / root;  // L / 2 x sin theta
      const double rho0 = std::max(root * height, 1e-9 * len);
      if (!Fits(rho0, mu, reach, room, /*sides=*/2)) return;
      for (double rho = rho0; rho < reach; rho *= mu) {
        if (foot - rho > 0) extra->push_back({e, (foot - rho) / len});
        if (foot + rho < len) extra->push_back({e, (foot + rho) / len});
      }
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh_.FaceVertex(f, k);
      if (!std::isfinite(radius[v])) continue;
      const Vec p = mesh_.Position(v);
      const double start = std::max(epsilon / 8 * Dist(q.pos, p) * w_ratio[v], 1e-9 * radius[v]);
      if (start < radius[v]) reach_down->push_back({v, start});
    }
  }
}

void SteinerGraph::AddVicinityPoints(std::vector<std::pair<uint32_t, double>> reach_down,
                                     const std::vector<double>& lambda,
                                     const std::vector<double>& radius,
                                     std::vector<std::pair<uint32_t, double>>* extra,
                                     uint64_t* room) const {
  // One continuation per vertex, down to the smallest start its anchors ask for: anchors around
  // the same vertex share its points.
  std::sort(reach_down.begin(), reach_down.end());
  for (size_t i = 0; i < reach_down.size(); ++i) {
    const auto [v, start] = reach_down[i];
    if (i > 0 && reach_down[i - 1].first == v) continue;
    for (const uint32_t* c = mesh_.CornersBegin(v); c != mesh_.CornersEnd(v); ++c) {
      for (const uint32_t h : {*c, TriangleMesh::Prev(*c)}) {
        const uint32_t e = edge_of_half_[h];
        if (lambda[e] == 0) continue;
        const uint32_t h0 = edge_half_[e];
        const bool at_from = mesh_.From(h0) == v;
        const double len = mesh_.Length(h0);
        if (!Fits(start, lambda[e], radius[v], room)) return;
        for (double r = radius[v] / lambda[e]; r >= start; r /= lambda[e]) {
          if (r < len / 2) extra->push_back({e, at_from ? r / len : 1 - r / len});
        }
      }
    }
  }
}

absl::Status SteinerGraph::Build(double epsilon, uint64_t max_points, Placement placement,
                                 const std::vector<Vec>& seeds,
                                 const std::vector<Located>& anchors) {
  const uint32_t nf = mesh_.face_count();
  auto usable = [&](uint32_t f) {
    return std::isfinite(FaceWeight(f)) && !mesh_.FaceDegenerate(f);
  };
  // Per vertex: the vicinity radius r(v).
  std::vector<double> d(nv_, kInf), wmin(nv_, kInf), wmax(nv_, 0), radius(nv_, kInf);
  for (uint32_t f = 0; f < nf; ++f) {
    if (!usable(f)) continue;
    const double w = FaceWeight(f);
    for (int k = 0; k < 3; ++k) {
      const uint32_t c = 3 * f + k;
      const uint32_t v = mesh_.FaceVertex(f, k);
      const double height =
          mesh_.Length(3 * f) * mesh_.OppY(3 * f) / mesh_.Length(TriangleMesh::Next(c));
      d[v] = std::min(d[v], height);
      wmin[v] = std::min(wmin[v], w);
      wmax[v] = std::max(wmax[v], w);
    }
  }
  std::vector<double> w_ratio(nv_, 0);
  for (uint32_t v = 0; v < nv_; ++v) {
    if (std::isfinite(d[v]) && d[v] > 0) {
      w_ratio[v] = wmin[v] / wmax[v];
      radius[v] = epsilon / 8 * d[v] * w_ratio[v];
    }
  }
  // Edges: one id per twin pair (or boundary half-edge).
  edge_of_half_.assign(3 * static_cast<size_t>(nf), kNoIndex);
  for (uint32_t h = 0; h < 3 * nf; ++h) {
    const uint32_t t = mesh_.Twin(h);
    if (t != kNoIndex && t < h) continue;
    edge_of_half_[h] = static_cast<uint32_t>(edge_half_.size());
    if (t != kNoIndex) edge_of_half_[t] = edge_of_half_[h];
    edge_half_.push_back(h);
  }
  const uint32_t ne = static_cast<uint32_t>(edge_half_.size());
  edge_weight_.assign(ne, kInf);
  std::vector<double> lambda(ne, 0);
  std::vector<uint32_t> count_a(ne, 0), count_b(ne, 0);
  const double root = std::sqrt(epsilon / 2);
  const uint32_t uniform =
      static_cast<uint32_t>(std::max(1.0, std::min(std::ceil(1 / epsilon) - 1, 1e9)));
  uint64_t total = 0;
  for (uint32_t e = 0; e < ne; ++e) {
    const uint32_t h0 = edge_half_[e];
    double sin_theta = kInf;
    for (const uint32_t h : {h0, mesh_.Twin(h0)}) {
      if (h == kNoIndex) continue;
      const uint32_t f = TriangleMesh::FaceOf(h);
      edge_weight_[e] = std::min(edge_weight_[e], FaceWeight(f));
      if (!usable(f)) continue;
      for (const uint32_t c : {h, TriangleMesh::Next(h)}) {
        sin_theta = std::min(sin_theta, std::sin(std::min(mesh_.CornerAngle(c), kHalfPi)));
      }
    }
    if (!std::isfinite(sin_theta) || !(sin_theta > 0)) continue;  // no passable face: no points
    lambda[e] = 1 + root * sin_theta;
    if (!Placed(e)) continue;
    if (placement == Placement::kUniform) {  // (count_b stays 0)
      count_a[e] = uniform;
      if (!seeds.empty() && seeds.size() <= kMaxSeeds) {
        const Vec a = mesh_.Position(mesh_.From(h0)), b = mesh_.Position(mesh_.To(h0));
        const Vec mid = Lerp(a, b, 0.5);
        double reach = kInf;
        for (const Vec& s : seeds) reach = std::min(reach, Dist(mid, s));
        count_a[e] = GradedCount(uniform, mesh_.Length(h0), reach);
      }
      total += count_a[e];
      continue;
    }
    const double half = mesh_.Length(h0) / 2;
    count_a[e] = SideCount(radius[mesh_.From(h0)], lambda[e], half);
    count_b[e] = SideCount(radius[mesh_.To(h0)], lambda[e], half);
    total += uint64_t{count_a[e]} + count_b[e] + 1;
  }
  std::vector<std::pair<uint32_t, double>> extra;
  const uint64_t limit =
      max_points != 0 ? std::min<uint64_t>(max_points, kMaxNodes - nv_) : kMaxNodes - nv_;
  if (placement == Placement::kBounded && !anchors.empty() && total <= limit) {
    // What the anchors may add before the limit (over it, the check below fails).
    uint64_t room = limit - total + 1;
    std::vector<std::pair<uint32_t, double>> reach_down;
    for (const Located& q : anchors) {
      if (room > 0 && (q.canonical.kind == SurfacePoint::Kind::kFace ||
                       q.canonical.kind == SurfacePoint::Kind::kEdge)) {
        AddAnchorPoints(q, epsilon, lambda, radius, w_ratio, &extra, &reach_down, &room);
      }
    }
    if (room > 0) AddVicinityPoints(std::move(reach_down), lambda, radius, &extra, &room);
    // At most what they add (duplicates go below); out of room: over the limit.
    total += room > 0 ? extra.size() : limit - total + 1;
  }
  if (max_points != 0 && total > max_points) {
    return LimitExceededError(
        Limit::kSteinerPoints,
        absl::StrFormat("epsilon %g needs %d Steiner points on this mesh, more than the %d allowed",
                        epsilon, total, max_points));
  }
  if (total > kMaxNodes - nv_) {
    return LimitExceededError(
        Limit::kSteinerPoints,
        absl::StrFormat("epsilon %g needs %d Steiner points on this mesh, more than a solve can "
                        "index (%d)",
                        epsilon, total, kMaxNodes - nv_));
  }
  first_.assign(ne + 1, 0);
  param_.resize(total);
  uint32_t at = 0;
  for (uint32_t e = 0; e < ne; ++e) {
    first_[e] = at;
    if (lambda[e] == 0 || !Placed(e)) continue;
    const uint32_t h0 = edge_half_[e];
    const double len = mesh_.Length(h0);
    if (placement == Placement::kUniform) {
      for (uint32_t i = 1; i <= count_a[e]; ++i) param_[at++] = double(i) / (count_a[e] + 1);
      continue;
    }
    // r lambda^i by repeated products (a pow per point was a fifth of a short path query's time);
    // their drift, under 1e-13 relative, is kept off the midpoint so the chain stays increasing.
    const double below_mid = std::nextafter(0.5, 0.0);
    double reach = radius[mesh_.From(h0)];
    for (uint32_t i = 0; i < count_a[e]; ++i, reach *= lambda[e]) {
      param_[at++] = std::min(reach / len, below_mid);
    }
    param_[at++] = 0.5;
    at += count_b[e];
    reach = radius[mesh_.To(h0)];
    for (uint32_t i = 1; i <= count_b[e]; ++i, reach *= lambda[e]) {
      param_[at - i] = 1 - std::min(reach / len, below_mid);
    }
  }
  first_[ne] = at;
  param_.resize(at);
  if (!extra.empty()) MergeExtraPoints(std::move(extra));
  // Implicit edge count: per passable face, node pairs on different edges (Steiner to Steiner and
  // Steiner to the opposite vertex); per passable edge, its chain.
  for (uint32_t f = 0; f < nf; ++f) {
    if (!std::isfinite(FaceWeight(f))) continue;
    uint64_t k[3];
    for (int j = 0; j < 3; ++j) {
      const uint32_t e = edge_of_half_[3 * f + j];
      k[j] = first_[e + 1] - first_[e];
    }
    graph_edges_ += k[0] * k[1] + k[1] * k[2] + k[2] * k[0] + k[0] + k[1] + k[2];
  }
  for (uint32_t e = 0; e < ne; ++e) {
    if (std::isfinite(edge_weight_[e])) graph_edges_ += first_[e + 1] - first_[e] + 1;
  }
  return absl::OkStatus();
}

void SteinerGraph::MergeExtraPoints(std::vector<std::pair<uint32_t, double>> extra) {
  std::sort(extra.begin(), extra.end());
  const uint32_t ne = edge_count();
  std::vector<uint32_t> first(ne + 1, 0);
  std::vector<double> param;
  param.reserve(param_.size() + extra.size());
  size_t x = 0;
  std::vector<double> chain;
  for (uint32_t e = 0; e < ne; ++e) {
    first[e] = static_cast<uint32_t>(param.size());
    if (x == extra.size() || extra[x].first != e) {
      param.insert(param.end(), param_.begin() + first_[e], param_.begin() + first_[e + 1]);
      continue;
    }
    chain.assign(param_.begin() + first_[e], param_.begin() + first_[e + 1]);
    for (; x < extra.size() && extra[x].first == e; ++x) {
      const double t = extra[x].second;
      if (t > 0 && t < 1) chain.push_back(t);
    }
    std::sort(chain.begin(), chain.end());
    chain.erase(std::unique(chain.begin(), chain.end()), chain.end());
    param.insert(param.end(), chain.begin(), chain.end());
  }
  first[ne] = static_cast<uint32_t>(param.size());
  first_ = std::move(first);
  param_ = std::move(param);
}

absl::StatusOr<Located> Locate(const TriangleMesh& mesh, const SurfacePoint& p) {
  if (absl::Status s = ValidateSurfacePoint(mesh, p); !s.ok()) return s;
  Located out;
  out.canonical = CanonicalPoint(mesh, p);
  const SurfacePoint& c = out.canonical;
  switch (c.kind) {
    case SurfacePoint::Kind::kVertex:
      InternalCopies(mesh, c.vertex, &out.vertices);
      out.pos = mesh.Position(c.vertex);
      break;
    case SurfacePoint::Kind::kEdge: {
      HalfEdgesOfFileEdge(mesh, c.edge_from, c.edge_to, &out.half_edges);
      if (out.half_edges.empty()) {
        return absl::InvalidArgumentError(
            absl::StrFormat("point %s: the mesh has no edge between vertices %d and %d",
                            SurfacePointToString(p), c.edge_from, c.edge_to));
      }
      const uint32_t h = out.half_edges[0];
      const bool forward = mesh.FileVertex(mesh.From(h)) == c.edge_from;
      const Vec a = mesh.Position(forward ? mesh.From(h) : mesh.To(h));
      const Vec b = mesh.Position(forward ? mesh.To(h) : mesh.From(h));
      out.pos = SteinerGraph::Lerp(a, b, c.t);
      break;
    }
    case SurfacePoint::Kind::kFace: {
      out.face = c.face;
      std::array<double, 3> ib = c.bary;
      mesh.SwapCornerOrder(c.face, &ib);
      out.pos = {0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        const Vec q = mesh.Position(mesh.FaceVertex(c.face, k));
        for (int j = 0; j < 3; ++j) out.pos[j] += ib[k] * q[j];
      }
      break;
    }
    case SurfacePoint::Kind::kPosition:
      break;  // rejected by ValidateSurfacePoint
  }
  return out;
}

// What a straight link runs in: nothing (a vertex point and its internal copies), a face or an
// edge (along it).
struct Medium {
  enum Kind : uint8_t { kSame, kFace, kEdge } kind;
  uint32_t id;
};

// The cost of a straight piece, by what it runs in: weight x 3D length. (x, y, z) is the piece in
// the search's direction.
class IsotropicCost {
 public:
  explicit IsotropicCost(const SteinerGraph& g) : g_(g) {}
  // Links only: every cost is a real path's, so the bound holds (see Search::CrossSegments).
  static constexpr bool kInterpolates = false;
  double Face(uint32_t f, double x, double y, double z) const {
    return g_.FaceWeight(f) * std::sqrt(x * x + y * y + z * z);
  }
  double Edge(uint32_t e, double x, double y, double z) const {
    return g_.EdgeWeight(e) * std::sqrt(x * x + y * y + z * z);
  }
  // A lower bound on Face(f, ...) per metre of 3D length (here the cost itself).
  double FaceFloor(uint32_t f) const { return g_.FaceWeight(f); }
  // Face(f, ...) with f's values read once (a relaxation evaluates many pieces in one face).
  struct FaceWalk {
    double w;
    double operator()(double x, double y, double z) const {
      return w * std::sqrt(x * x + y * y + z * z);
    }
  };
  FaceWalk ForFace(uint32_t f) const { return {g_.FaceWeight(f)}; }

 private:
  const SteinerGraph& g_;
};

// The cost of a straight piece under a slope cost (weighted_field.h's SlopeCost): weight x 3D
// length x the cost per metre of its slope, or inside a face's switchback range the zigzag's cost
// (the face's convex envelope). The search runs from the sources; with `inbound` the walker goes
// the other way, so a piece's rise changes sign.
class DirectionalCost {
 public:
  // No bound to keep: the wave also crosses between settled nodes (Search::CrossSegments).
  static constexpr bool kInterpolates = true;
  DirectionalCost(const SteinerGraph& g, const SlopeCost& slope, bool inbound)
      : g_(g),
        table_(slope.per_metre),
        sign_(inbound ? -1 : 1),
        cheapest_(*std::min_element(table_.begin(), table_.end())) {
    const TriangleMesh& mesh = g.mesh();
    const uint32_t nf = mesh.face_count();
    inv_sin_.assign(nf, 0);
    // A face's switchback ranges depend on its slope alone, and a DEM's faces share few slopes
    // (Jacksboro: 8,171 among 276k faces): each distinct slope's envelope is built once.
    shape_of_.assign(nf, 0);
    shape_first_ = {0, 0};  // shape 0: no ranges (level or impassable faces)
    std::unordered_map<double, uint32_t> shape_of_slope;
    for (uint32_t f = 0; f < nf; ++f) {
      if (!std::isfinite(g.FaceWeight(f)) || mesh.FaceDegenerate(f)) continue;
      const Vec a = mesh.Position(mesh.FaceVertex(f, 0)), b = mesh.Position(mesh.FaceVertex(f, 1)),
                c = mesh.Position(mesh.FaceVertex(f, 2));
      const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
      const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
      const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      const double sin_slope = std::hypot(nx, ny) / std::sqrt(nx * nx + ny * ny + nz * nz);
      if (!(sin_slope > 1e-12)) continue;  // level: the same cost every way, nothing to envelope
      inv_sin_[f] = 1 / sin_slope;
      const auto [at, added] =
          shape_of_slope.try_emplace(sin_slope, static_cast<uint32_t>(shape_first_.size() - 1));
      if (added) {
        AddSwitchbacks(sin_slope);
        shape_first_.push_back(static_cast<uint32_t>(chords_.size()));
      }
      shape_of_[f] = at->second;
    }
    // Along an edge: the cheaper of its passable faces, per direction (walker's).
    const uint32_t ne = g.edge_count();
    edge_dir_.assign(3 * size_t{ne}, 0);
    edge_fwd_.assign(ne, kInf);
    edge_bwd_.assign(ne, kInf);
    for (uint32_t e = 0; e < ne; ++e) {
      const uint32_t h0 = g.EdgeHalf(e);
      const Vec p = mesh.Position(mesh.From(h0)), q = mesh.Position(mesh.To(h0));
      const double len = Dist(p, q);
      if (!(len > 0)) continue;
      const double dx = (q[0] - p[0]) / len, dy = (q[1] - p[1]) / len, dz = (q[2] - p[2]) / len;
      edge_dir_[3 * e] = dx;
      edge_dir_[3 * e + 1] = dy;
      edge_dir_[3 * e + 2] = dz;
      for (const uint32_t h : {h0, mesh.Twin(h0)}) {
        if (h == kNoIndex) continue;
        const uint32_t f = TriangleMesh::FaceOf(h);
        if (!std::isfinite(g.FaceWeight(f))) continue;
        edge_fwd_[e] = std::min(edge_fwd_[e], Walk(f, dx, dy, dz));
        edge_bwd_[e] = std::min(edge_bwd_[e], Walk(f, -dx, -dy, -dz));
      }
    }
  }

  double Face(uint32_t f, double x, double y, double z) const { return ForFace(f)(x, y, z); }
  double Edge(uint32_t e, double x, double y, double z) const {
    const double len = std::sqrt(x * x + y * y + z * z);
    if (len == 0) return 0;
    const double along =
        sign_ * (x * edge_dir_[3 * e] + y * edge_dir_[3 * e + 1] + z * edge_dir_[3 * e + 2]);
    return len * (along >= 0 ? edge_fwd_[e] : edge_bwd_[e]);
  }
  // A lower bound on Face(f, ...) per metre: the weight x the cheapest sample. The envelope's
  // unit-cost set is the hull of samples no farther than 1 / cheapest, so it holds for zigzags too.
  double FaceFloor(uint32_t f) const { return g_.FaceWeight(f) * cheapest_; }

 private:
  // A switchback range of a face: for slope sines in [lo, hi] the cost of a piece is
  // weight x (up_cost x its uphill component + across_cost x its across-slope component).
  struct Chord {
    double lo, hi, up_cost, across_cost;
  };

  // Cost per metre at slope sine `sine` (linear between samples).
  static double Interpolate(const std::vector<double>& table, double sine) {
    const double at = (std::clamp(sine, -1.0, 1.0) + 1) * 0.5 * (table.size() - 1);
    const size_t i = std::min(static_cast<size_t>(at), table.size() - 2);
    const double t = at - i;
    if (t == 0) return table[i];
    if (t == 1) return table[i + 1];
    return table[i] + t * (table[i + 1] - table[i]);  // +inf stays +inf
  }
  double PerMetre(double sine) const { return Interpolate(table_, sine); }

 public:
  // The walker's cost of pieces inside one face, what a face's values read once (a relaxation
  // evaluates many pieces in one face).
  struct FaceWalk {
    const std::vector<double>* table;
    const Chord* chord;
    const Chord* chord_end;
    double w, inv_sin, sign;
    // The cost of the piece (x, y, z) in the search's direction.
    double operator()(double x, double y, double z) const {
      const double len2 = x * x + y * y + z * z;
      if (len2 == 0) return 0;
      const double len = std::sqrt(len2);
      const double rise = sign * z;
      const double sine = rise / len;
      for (const Chord* c = chord; c != chord_end; ++c) {
        if (sine < c->lo || sine > c->hi) continue;
        if (!std::isfinite(c->up_cost)) return kInf;  // a range no zigzag can walk
        const double up = rise * inv_sin;
        const double across = std::sqrt(std::max(0.0, len2 - up * up));
        return w * (c->up_cost * up + c->across_cost * across);
      }
      return w * len * Interpolate(*table, sine);
    }
  };
  FaceWalk ForFace(uint32_t f) const { return WalkOf(f, sign_); }

 private:
  FaceWalk WalkOf(uint32_t f, double sign) const {
    return {&table_,
            chords_.data() + shape_first_[shape_of_[f]],
            chords_.data() + shape_first_[shape_of_[f] + 1],
            g_.FaceWeight(f),
            inv_sin_[f],
            sign};
  }
  // The walker's cost of the piece (x, y, z) inside face f.
  double Walk(uint32_t f, double x, double y, double z) const { return WalkOf(f, 1)(x, y, z); }

  // The convex envelope of a face of slope sine `sin_slope`. In the face's frame (x uphill, y
  // across), the set a walker reaches at cost 1 going straight is bounded by the points
  // (cos phi, sin phi) / cost(phi), cost(phi) = PerMetre(sin_slope cos phi); zigzags reach its
  // convex hull. The cost is symmetric in y, so the upper half (phi in [0, pi]) is built: a Graham
  // scan over the samples in angular order, with the two axis points of the hull (x = the largest
  // and the smallest sample x, where a symmetric convex set crosses its axis). Hull edges that
  // skip samples are switchback ranges.
  void AddSwitchbacks(double sin_slope) {
    constexpr int kSteps = 360;  // half-degree samples
    struct Angles {              // cos and sin of the samples' angles, once per process
      std::array<double, kSteps + 1> cos, sin;
      Angles() {
        for (int j = 0; j <= kSteps; ++j) {
          cos[j] = std::cos(M_PI * j / kSteps);
          sin[j] = std::sin(M_PI * j / kSteps);
        }
      }
    };
    static const Angles angles;
    std::array<double, kSteps + 1> px, py;
    double xmax = -kInf, xmin = kInf;
    for (int j = 0; j <= kSteps; ++j) {
      const double cost = PerMetre(sin_slope * angles.cos[j]);
      const double r = std::isfinite(cost) ? 1 / cost : 0;
      px[j] = r * angles.cos[j];
      py[j] = j == 0 || j == kSteps ? 0 : r * angles.sin[j];
      xmax = std::max(xmax, px[j]);
      xmin = std::min(xmin, px[j]);
    }
    const bool axis0 = xmax > px[0], axis_pi = xmin < px[kSteps];  // hull points off the samples
    px[0] = xmax;
    px[kSteps] = xmin;
    std::array<int, kSteps + 1> hull;
    int top = 0;
    for (int j = 0; j <= kSteps; ++j) {
      while (top >= 2) {
        const int a = hull[top - 2], b = hull[top - 1];
        const double cross = (px[b] - px[a]) * (py[j] - py[a]) - (py[b] - py[a]) * (px[j] - px[a]);
        if (cross > 0) break;
        --top;
      }
      hull[top++] = j;
    }
    for (int i = 0; i + 1 < top; ++i) {
      const int a = hull[i], b = hull[i + 1];
      if (b == a + 1 && !(a == 0 && axis0) && !(b == kSteps && axis_pi)) continue;  // the curve
      // The hull edge's line n . p = h, n outward: the gauge of d is n . d / h.
      const double nx = py[b] - py[a], ny = px[a] - px[b];
      const double h = nx * px[a] + ny * py[a];
      Chord c;
      c.lo = sin_slope * angles.cos[b];
      c.hi = sin_slope * angles.cos[a];
      c.up_cost = h > 0 ? nx / h : kInf;
      c.across_cost = h > 0 ? ny / h : kInf;
      chords_.push_back(c);
    }
  }

  const SteinerGraph& g_;
  const std::vector<double>& table_;
  double sign_;
  double cheapest_;  // the table's least cost per metre
  std::vector<double> inv_sin_;
  std::vector<uint32_t> shape_of_;     // per face: its slope's shape
  std::vector<uint32_t> shape_first_;  // per shape: its first chord (and a sentinel)
  std::vector<Chord> chords_;
  std::vector<double> edge_dir_, edge_fwd_, edge_bwd_;
};

template <typename Cost>
double LinkCost(const Cost& cost, Medium m, const Vec& from, const Vec& to) {
  const double x = to[0] - from[0], y = to[1] - from[1], z = to[2] - from[2];
  switch (m.kind) {
    case Medium::kSame:
      return 0;
    case Medium::kFace:
      return cost.Face(m.id, x, y, z);
    case Medium::kEdge:
      return cost.Edge(m.id, x, y, z);
  }
  return kInf;
}

// Calls fn(node, medium) for every node a point links to straight (what the segment runs in; a
// node may come more than once). A vertex point links to its copies through kSame.
template <typename Fn>
void ForEachLink(const SteinerGraph& g, const Located& p, Fn&& fn) {
  const TriangleMesh& mesh = g.mesh();
  auto edge_nodes = [&](uint32_t h, Medium m) {
    const uint32_t e = g.EdgeOfHalf(h);
    for (uint32_t n = g.First(e); n < g.End(e); ++n) fn(n, m);
  };
  auto face_nodes = [&](uint32_t h) {  // the face of h, except the open edge h
    const uint32_t f = TriangleMesh::FaceOf(h);
    if (!std::isfinite(g.FaceWeight(f))) return;
    const Medium m{Medium::kFace, f};
    edge_nodes(TriangleMesh::Next(h), m);
    edge_nodes(TriangleMesh::Prev(h), m);
    fn(mesh.Opposite(h), m);
  };
  switch (p.canonical.kind) {
    case SurfacePoint::Kind::kVertex:
      for (const uint32_t v : p.vertices) fn(v, Medium{Medium::kSame, 0});
      break;
    case SurfacePoint::Kind::kEdge:
      for (const uint32_t h : p.half_edges) {
        const uint32_t e = g.EdgeOfHalf(h);
        if (std::isfinite(g.EdgeWeight(e))) {
          const Medium m{Medium::kEdge, e};
          edge_nodes(h, m);
          fn(mesh.From(h), m);
          fn(mesh.To(h), m);
        }
        face_nodes(h);
      }
      break;
    case SurfacePoint::Kind::kFace: {
      if (!std::isfinite(g.FaceWeight(p.face))) break;
      const Medium m{Medium::kFace, p.face};
      for (int k = 0; k < 3; ++k) {
        edge_nodes(3 * p.face + k, m);
        fn(mesh.FaceVertex(p.face, k), m);
      }
      break;
    }
    case SurfacePoint::Kind::kPosition:
      break;
  }
}

// The cost of the straight segment from a to b when they share a face or an edge (+inf
// otherwise).
template <typename Cost>
double DirectCost(const SteinerGraph& g, const Cost& cost, const Located& a, const Located& b) {
  const TriangleMesh& mesh = g.mesh();
  // Faces and edges holding each point.
  auto supports = [&](const Located& p, std::vector<uint32_t>* faces,
                      std::vector<uint32_t>* edges) {
    switch (p.canonical.kind) {
      case SurfacePoint::Kind::kVertex:
        for (const uint32_t v : p.vertices) {
          for (const uint32_t* c = mesh.CornersBegin(v); c != mesh.CornersEnd(v); ++c) {
            faces->push_back(TriangleMesh::FaceOf(*c));
            edges->push_back(g.EdgeOfHalf(*c));
            edges->push_back(g.EdgeOfHalf(TriangleMesh::Prev(*c)));
          }
        }
        break;
      case SurfacePoint::Kind::kEdge:
        for (const uint32_t h : p.half_edges) {
          faces->push_back(TriangleMesh::FaceOf(h));
          edges->push_back(g.EdgeOfHalf(h));
        }
        break;
      case SurfacePoint::Kind::kFace:
        faces->push_back(p.face);
        break;
      case SurfacePoint::Kind::kPosition:
        break;
    }
  };
  std::vector<uint32_t> fa, ea, fb, eb;
  supports(a, &fa, &ea);
  supports(b, &fb, &eb);
  double best = kInf;
  for (const uint32_t f : fa) {
    if (std::isfinite(g.FaceWeight(f)) && std::find(fb.begin(), fb.end(), f) != fb.end()) {
      best = std::min(best, LinkCost(cost, Medium{Medium::kFace, f}, a.pos, b.pos));
    }
  }
  for (const uint32_t e : ea) {
    if (std::isfinite(g.EdgeWeight(e)) && std::find(eb.begin(), eb.end(), e) != eb.end()) {
      best = std::min(best, LinkCost(cost, Medium{Medium::kEdge, e}, a.pos, b.pos));
    }
  }
  return best;
}

// Where a search is headed (A*): a ball around its targets and a least cost per metre of any
// link, so that per_metre x (the distance to the ball) is a lower bound of the cost left: a
// consistent heuristic (a link costs at least per_metre x its length, which is at least the
// change in that distance).
struct Goal {
  Vec centre{};
  double radius = 0;
  double per_metre = 0;
};

// Bit j of the result: node j of a chain (cost c[j], at a + t[j] d relative to the settled point)
// might be improved by a link from the settled point, of cost `base` + length x at least
// 1 / per_metre: the link's squared length is below the node's room squared, loosened by 1e-9 so
// rounding never drops an improvement. Settled nodes (c[j] <= base) and nodes already cheaper
// than any link could make them are not marked. count <= 64.
constexpr double kSlack = 1 + 1e-9;

// MarkCandidates' test for nodes j.. count-1, one at a time.
inline uint64_t MarkRest(const double* c, const double* t, uint32_t j, uint32_t count, double base,
                         double per_metre, const Vec& a, const Vec& d) {
  uint64_t hits = 0;
  for (; j < count; ++j) {
    const double room = (c[j] - base) * per_metre;
    const double x = a[0] + t[j] * d[0], y = a[1] + t[j] * d[1], z = a[2] + t[j] * d[2];
    const bool hit = (room > 0) & (x * x + y * y + z * z < room * room * kSlack);
    hits |= uint64_t{hit} << j;
  }
  return hits;
}

inline uint64_t MarkCandidates(const double* c, const double* t, uint32_t count, double base,
                               double per_metre, const Vec& a, const Vec& d) {
  uint64_t hits = 0;
  uint32_t j = 0;
#if defined(__SSE2__)
  const __m128d vbase = _mm_set1_pd(base), vper = _mm_set1_pd(per_metre);
  const __m128d vslack = _mm_set1_pd(kSlack), zero = _mm_setzero_pd();
  const __m128d ax = _mm_set1_pd(a[0]), ay = _mm_set1_pd(a[1]), az = _mm_set1_pd(a[2]);
  const __m128d dx = _mm_set1_pd(d[0]), dy = _mm_set1_pd(d[1]), dz = _mm_set1_pd(d[2]);
  for (; j + 2 <= count; j += 2) {
    const __m128d room = _mm_mul_pd(_mm_sub_pd(_mm_loadu_pd(c + j), vbase), vper);
    const __m128d s = _mm_loadu_pd(t + j);
    const __m128d x = _mm_add_pd(ax, _mm_mul_pd(s, dx));
    const __m128d y = _mm_add_pd(ay, _mm_mul_pd(s, dy));
    const __m128d z = _mm_add_pd(az, _mm_mul_pd(s, dz));
    const __m128d len2 =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(x, x), _mm_mul_pd(y, y)), _mm_mul_pd(z, z));
    const __m128d hit = _mm_and_pd(_mm_cmpgt_pd(room, zero),
                                   _mm_cmplt_pd(len2, _mm_mul_pd(_mm_mul_pd(room, room), vslack)));
    hits |= uint64_t(_mm_movemask_pd(hit)) << j;
  }
#endif
  return hits | MarkRest(c, t, j, count, base, per_metre, a, d);
}

#if defined(GEODEX_AVX2_FILTER)
// MarkCandidates four nodes per instruction, the same operations per lane (AVX2 without FMA: no
// contraction), so the same marks. Called only where the CPU has AVX2 (kHasAvx2).
__attribute__((target("avx2"))) uint64_t MarkCandidatesAvx2(const double* c, const double* t,
                                                            uint32_t count, double base,
                                                            double per_metre, const Vec& a,
                                                            const Vec& d) {
  uint64_t hits = 0;
  uint32_t j = 0;
  const __m256d vbase = _mm256_set1_pd(base), vper = _mm256_set1_pd(per_metre);
  const __m256d vslack = _mm256_set1_pd(kSlack), zero = _mm256_setzero_pd();
  const __m256d ax = _mm256_set1_pd(a[0]), ay = _mm256_set1_pd(a[1]), az = _mm256_set1_pd(a[2]);
  const __m256d dx = _mm256_set1_pd(d[0]), dy = _mm256_set1_pd(d[1]), dz = _mm256_set1_pd(d[2]);
  for (; j + 4 <= count; j += 4) {
    const __m256d room = _mm256_mul_pd(_mm256_sub_pd(_mm256_loadu_pd(c + j), vbase), vper);
    const __m256d s = _mm256_loadu_pd(t + j);
    const __m256d x = _mm256_add_pd(ax, _mm256_mul_pd(s, dx));
    const __m256d y = _mm256_add_pd(ay, _mm256_mul_pd(s, dy));
    const __m256d z = _mm256_add_pd(az, _mm256_mul_pd(s, dz));
    const __m256d len2 =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), _mm256_mul_pd(z, z));
    const __m256d hit = _mm256_and_pd(
        _mm256_cmp_pd(room, zero, _CMP_GT_OQ),
        _mm256_cmp_pd(len2, _mm256_mul_pd(_mm256_mul_pd(room, room), vslack), _CMP_LT_OQ));
    hits |= uint64_t(_mm256_movemask_pd(hit)) << j;
  }
  return hits | MarkRest(c, t, j, count, base, per_metre, a, d);
}
const bool kHasAvx2 = __builtin_cpu_supports("avx2");
#endif

// Dijkstra over the implicit graph, nodes settled in order of (cost, node id). The queue is an
// indexed binary heap of buckets, not of nodes: a bucket is a vertex or one edge's chain of
// Steiner points, keyed by its least unsettled node. A node's cost drops about a hundred times
// before it settles (each settled neighbour across a face offers a better link); in a bucket most
// drops leave its least node alone and cost no heap work, and the heap is an edge count, not a
// node count, deep. Settling a chain's least node rescans the chain. Cost: IsotropicCost or
// DirectionalCost (a template, so the inner loop has no virtual call). kHeaded: A* (HeadFor),
// ordered by (cost + a lower bound of the cost left, node id); a template too, so a whole field's
// search pays nothing for it.
template <typename Cost, bool kHeaded = false>
class Search {
 public:
  Search(const SteinerGraph& g, const Cost& cost)
      : g_(g),
        costs_(cost),
        mesh_(g.mesh()),
        least_(g.nv() + g.edge_count(), kNoIndex),
        slot_(g.nv() + g.edge_count(), kNoIndex),
        run_lo_(g.edge_count(), kNoIndex),
        run_hi_(g.edge_count(), kNoIndex),
        chain_max_(g.edge_count(), kInf) {
    // A headed search reaches a part of the surface: its Steiner nodes' state is written per edge
    // as the wave first reaches the edge (Touch), so a short path query neither writes nor maps
    // the pages of the rest (on Jacksboro at epsilon 0.01, 25 bytes x 6.7M nodes). A whole search
    // writes it all at once.
    const uint32_t n = kHeaded ? g.nv() : g.node_count();
    cost_.resize(g.node_count());
    label_.resize(g.node_count());
    parent_.resize(g.node_count());
    done_.resize(g.node_count());
    if constexpr (kHeaded) ahead_.resize(g.node_count());
    Reset(0, n);
    if constexpr (kHeaded) touched_.assign(g.edge_count(), 0);
  }

  // Orders the search by cost + a lower bound of the cost left to `goal` (A*) instead of by cost.
  // Every node it settles has its least cost, as with Dijkstra, and those costs are Dijkstra's
  // bit for bit (a node's cost is the least of its settled neighbours' offers, whatever their
  // order); it settles fewer. For a search with targets only: costs away from them stay high.
  void HeadFor(const Goal& goal) {
    static_assert(kHeaded, "a Search<Cost, true> heads for a goal");
    goal_ = goal;
  }

  // The bucket of a node: the vertex itself, or nv + its edge.
  uint32_t BucketOf(uint32_t node) const {
    return node < g_.nv() ? node : g_.nv() + g_.EdgeOfNode(node);
  }
  // The position of a node of `bucket` (no search for its edge, as SteinerGraph::Pos needs).
  Vec PosOf(uint32_t node, uint32_t bucket) const {
    return node < g_.nv() ? mesh_.Position(node) : g_.PosOn(node, bucket - g_.nv());
  }

  void Offer(uint32_t node, uint32_t bucket, double cost, uint32_t label, uint32_t parent) {
    ++relaxations_;
    Improve(node, bucket, cost, label, parent);
  }
  // Offer without the count (RelaxEdge counts its links in bulk).
  void Improve(uint32_t node, uint32_t bucket, double cost, uint32_t label, uint32_t parent) {
    Touch(bucket);
    if (!(cost < cost_[node])) return;
    if constexpr (kHeaded) {
      if (cost_[node] == kInf) ahead_[node] = Ahead(node, bucket);
    }
    cost_[node] = cost;
    label_[node] = label;
    parent_[node] = parent;
    const uint32_t least = least_[bucket];
    if (least == kNoIndex) {
      least_[bucket] = node;
      slot_[bucket] = static_cast<uint32_t>(heap_.size());
      heap_.push_back({Key(node), node, bucket});
      SiftUp(slot_[bucket]);
    } else if (node == least || Less(node, least)) {  // the bucket's key dropped
      least_[bucket] = node;
      heap_[slot_[bucket]] = {Key(node), node, bucket};
      SiftUp(slot_[bucket]);
    }
  }

  void Seed(const Located& p, uint32_t label) {
    const uint32_t parent =
        p.canonical.kind == SurfacePoint::Kind::kVertex ? kFromSourceVertex : kFromSourcePoint;
    ForEachLink(g_, p, [&](uint32_t n, Medium m) {
      Offer(n, BucketOf(n), LinkCost(costs_, m, p.pos, g_.Pos(n)), label, parent);
    });
  }

  // Runs until the heap is empty, the next cost exceeds max_distance, or stop(cost) says so;
  // settled(node) is called after each node is settled.
  template <typename Stop, typename Settled>
  absl::Status Run(const WeightedOptions& options, Stop&& stop, Settled&& settled) {
    uint32_t polls = 0;
    while (!heap_.empty()) {
      const uint32_t bucket = heap_[0].bucket;
      const uint32_t u = heap_[0].node;
      const double d = cost_[u];
      // Headed: the key is at most the cost of any target reached through u.
      const double key = Key(u);
      if (key > options.max_distance || stop(key)) break;
      done_[u] = 1;
      Refill(bucket);
      ++settled_;
      if (++polls == 4096) {
        polls = 0;
        if (options.cancel != nullptr && options.cancel->IsCancelled()) {
          return absl::CancelledError("weighted solve cancelled");
        }
      }
      Settle(u, bucket, d);
      settled(u);
    }
    peak_heap_ = std::max<uint64_t>(peak_heap_, heap_.capacity());
    return absl::OkStatus();
  }

  // Checks the search's result: no link from a settled node lowers any node's cost. Run after
  // the search (it relaxes every settled node's links again, as if unsettled, and compares).
  absl::Status CheckOptimality() {
    const std::vector<double> settled_cost(cost_.begin(), cost_.end());
    std::vector<uint32_t> settled;
    for (uint32_t n = 0; n < done_.size(); ++n) {
      if (done_[n]) settled.push_back(n);
    }
    std::fill(done_.begin(), done_.end(), 0);
    std::fill(run_lo_.begin(), run_lo_.end(), kNoIndex);
    checking_ = true;  // every link is evaluated, the lower-bound skip too is under test
    for (const uint32_t u : settled) Settle(u, BucketOf(u), settled_cost[u]);
    checking_ = false;
    for (uint32_t n = 0; n < cost_.size(); ++n) {
      if (cost_[n] < settled_cost[n]) {
        return absl::InternalError(
            absl::StrFormat("weighted search: node %d costs %.17g, a link offers %.17g", n,
                            settled_cost[n], cost_[n]));
      }
    }
    return absl::OkStatus();
  }

  // (A node of an edge the wave never reached: +inf, no label or parent.)
  double cost(uint32_t n) const { return Reached(n) ? cost_[n] : kInf; }
  uint32_t label(uint32_t n) const { return Reached(n) ? label_[n] : kNoIndex; }
  uint32_t parent(uint32_t n) const { return Reached(n) ? parent_[n] : kNoIndex; }
  // Nodes beyond max_distance (offered but not settled) become unreachable.
  void ClampTo(double max_distance) {
    for (size_t n = 0; n < cost_.size(); ++n) {
      if (cost_[n] > max_distance) {
        cost_[n] = kInf;
        label_[n] = kNoIndex;
        parent_[n] = kNoIndex;
      }
    }
  }

  WeightedStats Stats(double ms) const {
    WeightedStats s;
    s.nodes_settled = settled_;
    s.edge_relaxations = relaxations_;
    s.peak_bytes = g_.bytes() + cost_.size() * (sizeof(double) + 2 * sizeof(uint32_t) + 1) +
                   (least_.size() + run_lo_.size()) * 2 * sizeof(uint32_t) +
                   (chain_max_.size() + ahead_.size()) * sizeof(double) +
                   peak_heap_ * sizeof(Entry);
    s.solve_ms = ms;
    return s;
  }

 private:
  // Nodes [from, to) as no search has reached them.
  void Reset(uint32_t from, uint32_t to) {
    std::fill(cost_.begin() + from, cost_.begin() + to, kInf);
    std::fill(label_.begin() + from, label_.begin() + to, kNoIndex);
    std::fill(parent_.begin() + from, parent_.begin() + to, kNoIndex);
    std::fill(done_.begin() + from, done_.begin() + to, 0);
    if constexpr (kHeaded) std::fill(ahead_.begin() + from, ahead_.begin() + to, 0.0);
  }
  // Headed: the state of `bucket`'s nodes is written before the search first reads it.
  void Touch(uint32_t bucket) {
    if constexpr (kHeaded) {
      if (bucket < g_.nv()) return;
      const uint32_t e = bucket - g_.nv();
      if (touched_[e]) return;
      touched_[e] = 1;
      Reset(g_.First(e), g_.End(e));
    }
  }
  bool Reached(uint32_t n) const {
    if constexpr (kHeaded) return n < g_.nv() || touched_[g_.EdgeOfNode(n)];
    return true;
  }

  // The queue's order: (key, node id).
  double Key(uint32_t n) const {
    if constexpr (kHeaded) return cost_[n] + ahead_[n];
    return cost_[n];
  }
  bool Less(uint32_t a, uint32_t b) const {
    const double ka = Key(a), kb = Key(b);
    return ka < kb || (ka == kb && a < b);
  }
  // The lower bound of the cost left from node n (of `bucket`) to the goal.
  double Ahead(uint32_t n, uint32_t bucket) const {
    const Vec p = PosOf(n, bucket);
    const double away = Dist(p, goal_.centre) - goal_.radius;
    return away > 0 ? away * goal_.per_metre : 0;
  }
  // A heap entry: a bucket with its least node and that node's key, kept in the entry so that
  // sifting reads the heap alone (no lookups per comparison).
  struct Entry {
    double key;
    uint32_t node, bucket;
  };
  static bool Before(const Entry& a, const Entry& b) {
    return a.key < b.key || (a.key == b.key && a.node < b.node);  // as Less
  }
  void SiftUp(uint32_t i) {
    const Entry x = heap_[i];
    while (i > 0) {
      const uint32_t p = (i - 1) / 2;
      if (!Before(x, heap_[p])) break;
      heap_[i] = heap_[p];
      slot_[heap_[i].bucket] = i;
      i = p;
    }
    heap_[i] = x;
    slot_[x.bucket] = i;
  }
  void SiftDown(uint32_t i) {
    const Entry x = heap_[i];
    const uint32_t size = static_cast<uint32_t>(heap_.size());
    while (true) {
      uint32_t c = 2 * i + 1;
      if (c >= size) break;
      if (c + 1 < size && Before(heap_[c + 1], heap_[c])) ++c;
      if (!Before(heap_[c], x)) break;
      heap_[i] = heap_[c];
      slot_[heap_[i].bucket] = i;
      i = c;
    }
    heap_[i] = x;
    slot_[x.bucket] = i;
  }
  // The top bucket's least node was just settled: its next least unsettled node (with a cost)
  // becomes its key, or the bucket leaves the heap.
  void Refill(uint32_t bucket) {
    uint32_t least = kNoIndex;
    if (bucket >= g_.nv()) {
      const uint32_t e = bucket - g_.nv();
      const uint32_t first = g_.First(e), end = g_.End(e);
      const uint32_t settled = least_[bucket];
      // Grow the edge's settled run by the node just settled (and any settled nodes it joins).
      if (run_lo_[e] == kNoIndex) {
        run_lo_[e] = settled;
        run_hi_[e] = settled + 1;
      } else if (settled == run_hi_[e]) {
        ++run_hi_[e];
      } else if (settled + 1 == run_lo_[e]) {
        --run_lo_[e];
      }
      while (run_hi_[e] < end && done_[run_hi_[e]]) ++run_hi_[e];
      while (run_lo_[e] > first && done_[run_lo_[e] - 1]) --run_lo_[e];
      double best = kInf, most = 0;
      auto scan = [&](uint32_t from, uint32_t to) {
        for (uint32_t n = from; n < to; ++n) {
          if (done_[n]) continue;
          most = std::max(most, cost_[n]);
          const double key = Key(n);
          if (key < best) {  // (key, id): the first of equal keys wins
            best = key;
            least = n;
          }
        }
      };
      scan(first, run_lo_[e]);
      scan(run_hi_[e], end);
      chain_max_[e] = most;  // costs only drop: it stays an upper bound until the next rescan
    }
    least_[bucket] = least;
    if (least != kNoIndex) {
      heap_[0] = {Key(least), least, bucket};  // (the bucket is the heap's top)
      SiftDown(0);
      return;
    }
    peak_heap_ = std::max<uint64_t>(peak_heap_, heap_.size());
    slot_[bucket] = kNoIndex;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (heap_.empty()) return;
    heap_[0] = last;
    SiftDown(0);
  }

  // Relaxes the Steiner nodes of edge e from point p across face f.
  void RelaxEdge(uint32_t e, const Vec& p, double base, uint32_t f, uint32_t label, uint32_t from) {
    const uint32_t begin = g_.First(e), end = g_.End(e);
    if (begin == end) return;
    const uint32_t bucket = g_.nv() + e;
    Touch(bucket);
    const uint32_t h = g_.EdgeHalf(e);
    const Vec a = mesh_.Position(mesh_.From(h)), b = mesh_.Position(mesh_.To(h));
    const double ax = a[0] - p[0], ay = a[1] - p[1], az = a[2] - p[2];
    const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    // Most links cannot improve their node: skip them on a square-root-free lower bound, length
    // x the face's least cost per metre (slightly loosened, so rounding never skips an
    // improvement; the cost that is offered is computed in full). Settled nodes cost at most
    // `base`, so they fail it too.
    const double floor = costs_.FaceFloor(f);
    if (!checking_ && std::isfinite(chain_max_[e])) {
      // The whole chain: no link is shorter than the distance from p to the edge, so when that
      // costs more than the chain's costliest unsettled node, nothing can improve.
      const double sx = -ax, sy = -ay, sz = -az;  // p - a
      const double along =
          std::clamp((sx * dx + sy * dy + sz * dz) / (dx * dx + dy * dy + dz * dz), 0.0, 1.0);
      const double qx = sx - along * dx, qy = sy - along * dy, qz = sz - along * dz;
      if (base + floor * std::sqrt(qx * qx + qy * qy + qz * qz) * (1 - 1e-9) >= chain_max_[e]) {
        return;
      }
    }
    const double per_metre = checking_ ? kInf : 1 / floor;  // (check: no skips)
    const auto walk = costs_.ForFace(f);
    const double* param = g_.Params(begin);
    const double* cost = cost_.data();
    // The settled run is skipped whole; the nodes on either side are tested.
    const uint32_t run_lo = run_lo_[e] == kNoIndex ? end : run_lo_[e];
    const uint32_t run_hi = run_lo_[e] == kNoIndex ? end : run_hi_[e];
    relaxations_ += (run_lo - begin) + (end - run_hi);
    // In blocks of 64: a branch-free pass marks the candidates, then only they are offered.
    uint32_t count = 0;
    for (uint32_t block = begin; block < end; block += count) {
      if (block == run_lo) block = run_hi;
      if (block >= end) break;
      count = std::min<uint32_t>(64, (block < run_lo ? run_lo : end) - block);
      const double* c = cost + block;
      const double* t = param + (block - begin);
#if defined(GEODEX_AVX2_FILTER)
      uint64_t hits =
          kHasAvx2 ? MarkCandidatesAvx2(c, t, count, base, per_metre, {ax, ay, az}, {dx, dy, dz})
                   : MarkCandidates(c, t, count, base, per_metre, {ax, ay, az}, {dx, dy, dz});
#else
      uint64_t hits = MarkCandidates(c, t, count, base, per_metre, {ax, ay, az}, {dx, dy, dz});
#endif
      while (hits != 0) {
        const uint32_t j = static_cast<uint32_t>(__builtin_ctzll(hits));
        hits &= hits - 1;
        const uint32_t n = block + j;
        if (done_[n]) continue;  // settled (a zero-length link)
        const double x = ax + t[j] * dx, y = ay + t[j] * dy, z = az + t[j] * dz;
        Improve(n, bucket, base + walk(x, y, z), label, from);
      }
    }
  }
  // Relaxes node n (of `bucket`) from p through medium m.
  void RelaxNode(uint32_t n, uint32_t bucket, const Vec& p, double base, Medium m, uint32_t label,
                 uint32_t from) {
    Touch(bucket);
    if (done_[n]) return;
    Offer(n, bucket, base + LinkCost(costs_, m, p, PosOf(n, bucket)), label, from);
  }

  // The wave between two settled neighbours u and v on one edge crosses the segment [u, v]
  // anywhere, not only at its ends: a node x across face f (half-edge h of the edge in f) is
  // offered min over s of (1 - s) T(u) + s T(v) + cost(x - ((1 - s) u + s v)), the cost along the
  // segment taken as linear (the ordered upwind update of Sethian and Vladimirsky, 2003, on the
  // Steiner graph). Crossings between nodes cut the error of a graph path (which must bend at
  // nodes) from first to about second order in the spacing: a few times fewer points for the same
  // error. The offer is not a real path's cost, so it is used only where no bound is claimed (a
  // slope cost); it is clamped to at least T(u) so that costs still settle in order, and A* (whose
  // bound covers links) is off for such costs (GoalOf). The cost is convex in s (a convex face
  // cost along a line, plus a linear term), so a golden-section search finds the minimum.
  void CrossSegments(uint32_t f, uint32_t h, uint32_t u, const Vec& p, double dp,
                     std::array<uint32_t, 2> ends, uint32_t lab) {
    if (checking_) return;
    struct Segment {
      uint32_t v = kNoIndex;
      double dq, rx, ry, rz, r2;
    };
    std::array<Segment, 2> segs;
    int count = 0;
    for (const uint32_t v : ends) {
      if (v == kNoIndex || v == u || !done_[v]) continue;
      const Vec q = PosOf(v, v < g_.nv() ? v : g_.nv() + g_.EdgeOfHalf(h));
      Segment& sg = segs[count];
      sg.rx = q[0] - p[0], sg.ry = q[1] - p[1], sg.rz = q[2] - p[2];
      sg.r2 = sg.rx * sg.rx + sg.ry * sg.ry + sg.rz * sg.rz;
      if (!(sg.r2 > 0)) continue;
      sg.v = v;
      sg.dq = cost_[v];
      ++count;
    }
    if (count == 0) return;
    const auto walk = costs_.ForFace(f);
    const double floor = costs_.FaceFloor(f) * (1 - 1e-9);
    auto cross = [&](const Segment& sg, uint32_t n, uint32_t bucket, double xx, double xy,
                     double xz) {
      // Square-root-free skip: the lower end + floor x the distance to the segment cannot beat
      // the node.
      const double t = std::clamp((xx * sg.rx + xy * sg.ry + xz * sg.rz) / sg.r2, 0.0, 1.0);
      const double ox = xx - t * sg.rx, oy = xy - t * sg.ry, oz = xz - t * sg.rz;
      const double gap = cost_[n] - std::min(dp, sg.dq);
      if (gap * gap <= floor * floor * (ox * ox + oy * oy + oz * oz)) return;
      auto at = [&](double s) {
        return (1 - s) * dp + s * sg.dq + walk(xx - s * sg.rx, xy - s * sg.ry, xz - s * sg.rz);
      };
      // An interior minimum needs the cost falling at s = 0 and rising at s = 1 (convexity);
      // otherwise an end is best, and its link was offered already.
      constexpr double kNudge = 1e-3;
      if (!(at(kNudge) < at(0)) || !(at(1 - kNudge) < at(1))) return;
      // Golden section (the face's cost has kinks: Tobler's peak, the switchback ranges).
      constexpr double kGolden = 0.6180339887498949;
      double a = kNudge, b = 1 - kNudge;
      double c = b - kGolden * (b - a), e = a + kGolden * (b - a);
      double fc = at(c), fe = at(e);
      for (int i = 0; i < 8; ++i) {  // the bracket shrinks to 2% of the segment
        if (fc < fe) {
          b = e, e = c, fe = fc;
          c = b - kGolden * (b - a), fc = at(c);
        } else {
          a = c, c = e, fc = fe;
          e = a + kGolden * (b - a), fe = at(e);
        }
      }
      const double s = fc < fe ? c : e;
      const double cost = std::max(std::min(fc, fe), dp);
      ++relaxations_;
      Improve(n, bucket, cost, s < 0.5 ? lab : label_[sg.v], s < 0.5 ? u : sg.v);
    };
    auto offer = [&](uint32_t n, uint32_t bucket, const Vec& x) {
      if (done_[n] || cost_[n] <= dp) return;  // the clamped offer is at least dp
      // Only a node whose best link is from a segment's end: the wave reaches it across it.
      const uint32_t parent = parent_[n];
      const double xx = x[0] - p[0], xy = x[1] - p[1], xz = x[2] - p[2];
      for (int i = 0; i < count; ++i) {
        if (parent == u || parent == segs[i].v) cross(segs[i], n, bucket, xx, xy, xz);
      }
    };
    const uint32_t nv = g_.nv();
    for (const uint32_t t : {TriangleMesh::Next(h), TriangleMesh::Prev(h)}) {
      const uint32_t e = g_.EdgeOfHalf(t);
      const uint32_t first = g_.First(e), end = g_.End(e);
      if (first == end) continue;
      Touch(nv + e);
      const uint32_t he = g_.EdgeHalf(e);
      const Vec a = mesh_.Position(mesh_.From(he)), b = mesh_.Position(mesh_.To(he));
      const double* param = g_.Params(first);
      for (uint32_t n = first; n < end; ++n) {
        offer(n, nv + e, SteinerGraph::Lerp(a, b, param[n - first]));
      }
    }
    const uint32_t o = mesh_.Opposite(h);
    offer(o, o, mesh_.Position(o));
  }

  void Settle(uint32_t u, uint32_t bucket, double d) {
    const uint32_t nv = g_.nv();
    const Vec p = PosOf(u, bucket);
    const uint32_t lab = label_[u];
    if (u < g_.nv()) {
      for (const uint32_t* c = mesh_.CornersBegin(u); c != mesh_.CornersEnd(u); ++c) {
        // Along the two edges at u: the nearest node.
        const std::array<uint32_t, 2> at_u = {*c, TriangleMesh::Prev(*c)};
        std::array<uint32_t, 2> next = {kNoIndex, kNoIndex};
        for (int i = 0; i < 2; ++i) {
          const uint32_t h = at_u[i], e = g_.EdgeOfHalf(h);
          if (!std::isfinite(g_.EdgeWeight(e))) continue;
          if (g_.First(e) == g_.End(e)) {
            next[i] = mesh_.From(h) == u ? mesh_.To(h) : mesh_.From(h);
          } else {
            next[i] = mesh_.From(g_.EdgeHalf(e)) == u ? g_.First(e) : g_.End(e) - 1;
          }
          RelaxNode(next[i], next[i] < nv ? next[i] : nv + e, p, d, Medium{Medium::kEdge, e}, lab,
                    u);
        }
        // Across the face: the opposite edge's Steiner points.
        const uint32_t f = TriangleMesh::FaceOf(*c);
        if (std::isfinite(g_.FaceWeight(f))) {
          RelaxEdge(g_.EdgeOfHalf(TriangleMesh::Next(*c)), p, d, f, lab, u);
          if constexpr (Cost::kInterpolates) {
            // The segments from u to those nearest nodes (the face is passable, so both edges are).
            for (int i = 0; i < 2; ++i)
              CrossSegments(f, at_u[i], u, p, d, {next[i], kNoIndex}, lab);
          }
        }
      }
      return;
    }
    const uint32_t e = bucket - nv;
    const uint32_t h0 = g_.EdgeHalf(e);
    // u's neighbours along its edge: the previous and next Steiner nodes, or the edge's ends.
    const uint32_t before = u == g_.First(e) ? mesh_.From(h0) : u - 1;
    const uint32_t after = u + 1 == g_.End(e) ? mesh_.To(h0) : u + 1;
    if (std::isfinite(g_.EdgeWeight(e))) {  // (a Steiner node's edge has a passable face)
      const Medium along{Medium::kEdge, e};
      RelaxNode(before, before < nv ? before : bucket, p, d, along, lab, u);
      RelaxNode(after, after < nv ? after : bucket, p, d, along, lab, u);
    }
    for (const uint32_t h : {h0, mesh_.Twin(h0)}) {
      if (h == kNoIndex) continue;
      const uint32_t f = TriangleMesh::FaceOf(h);
      if (!std::isfinite(g_.FaceWeight(f))) continue;
      RelaxEdge(g_.EdgeOfHalf(TriangleMesh::Next(h)), p, d, f, lab, u);
      RelaxEdge(g_.EdgeOfHalf(TriangleMesh::Prev(h)), p, d, f, lab, u);
      if constexpr (Cost::kInterpolates) CrossSegments(f, h, u, p, d, {before, after}, lab);
      const uint32_t o = mesh_.Opposite(h);
      RelaxNode(o, o, p, d, Medium{Medium::kFace, f}, lab, u);
    }
  }

  const SteinerGraph& g_;
  const Cost& costs_;
  const TriangleMesh& mesh_;
  LazyVector<double> cost_;
  LazyVector<uint32_t> label_, parent_;
  LazyVector<uint8_t> done_;            // per node: settled
  std::vector<uint8_t> touched_;        // headed, per edge: its nodes' state is written (Touch)
  std::vector<uint32_t> least_, slot_;  // per bucket: least unsettled node, heap position
  // Per edge: a run [lo, hi) of its settled Steiner nodes, the first one settled and those that
  // joined it (on an edge the wave mostly settles outward from where it arrived); relaxations and
  // rescans skip it.
  std::vector<uint32_t> run_lo_, run_hi_;
  // Per edge: at least the cost of its costliest unsettled node (+inf until the edge's first
  // rescan, or while one is unreached); a relaxation that cannot beat it skips the chain.
  std::vector<double> chain_max_;
  bool checking_ = false;  // CheckOptimality is running
  Goal goal_;
  LazyVector<double> ahead_;  // headed: per node reached, Ahead(node)
  std::vector<Entry> heap_;   // buckets
  uint64_t settled_ = 0, relaxations_ = 0, peak_heap_ = 0;
};

double Elapsed(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Resolves the points (errors name the point as given).
absl::Status Prepare(const TriangleMesh& mesh, const std::vector<SurfacePoint>& points,
                     std::vector<Located>* located) {
  for (const SurfacePoint& p : points) {
    absl::StatusOr<Located> l = Locate(mesh, p);
    if (!l.ok()) return l.status();
    located->push_back(*std::move(l));
  }
  return absl::OkStatus();
}

// The best (cost, node) over the links of point t; node kNoIndex when the best is none.
template <typename Cost, bool kHeaded>
std::pair<double, uint32_t> BestLink(const SteinerGraph& g, const Cost& cost,
                                     const Search<Cost, kHeaded>& search, const Located& t) {
  double best = kInf;
  uint32_t node = kNoIndex;
  ForEachLink(g, t, [&](uint32_t n, Medium m) {
    const double c = search.cost(n);
    if (!std::isfinite(c)) return;
    const double total = c + LinkCost(cost, m, g.Pos(n), t.pos);
    if (total < best || (total == best && n < node)) {
      best = total;
      node = n;
    }
  });
  return {best, node};
}

// The goal of a search towards `to`: the ball around the targets' bounding box and the least
// cost per metre of any link (every passable face's floor; an edge link costs what one of its
// faces would), shaved so that rounding never makes the bound exceed a true cost.
template <typename Cost>
Goal GoalOf(const SteinerGraph& g, const Cost& cost, const std::vector<Located>& to) {
  Goal goal;
  // A segment's offer (Search::CrossSegments) is below its ends' links, outside what the bound
  // covers: such a search runs as Dijkstra (a zero bound) and still stops once its targets are
  // final, so its answers stay the whole search's bit for bit.
  if constexpr (Cost::kInterpolates) return goal;
  if (to.empty()) return goal;
  Vec lo = to[0].pos, hi = to[0].pos;
  for (const Located& t : to) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], t.pos[k]);
      hi[k] = std::max(hi[k], t.pos[k]);
    }
  }
  for (int k = 0; k < 3; ++k) goal.centre[k] = (lo[k] + hi[k]) / 2;
  for (const Located& t : to) goal.radius = std::max(goal.radius, Dist(t.pos, goal.centre));
  double floor = kInf;
  for (uint32_t f = 0; f < g.mesh().face_count(); ++f) {
    if (std::isfinite(g.FaceWeight(f))) floor = std::min(floor, cost.FaceFloor(f));
  }
  goal.per_metre = std::isfinite(floor) ? floor * (1 - 1e-9) : 0;
  return goal;
}

// Targets watched during a search, so that it can stop once each is final: per target its best
// cost so far, straight from a source or through a settled node linked to it. Once the next
// cost to settle exceeds every best, no link can lower one (an unsettled node costs at least
// that). The stop is strict, so every node a best could come through is settled, as in a whole
// search: the answers are the whole search's bit for bit.
template <typename Cost>
class TargetWatch {
 public:
  TargetWatch(const SteinerGraph& g, const Cost& cost, const std::vector<Located>& from,
              const std::vector<Located>& to)
      : g_(g), cost_(cost), to_(to), best_(to.size(), kInf) {
    for (uint32_t t = 0; t < to.size(); ++t) {
      ForEachLink(g, to[t], [&](uint32_t n, Medium m) { links_.push_back({n, t, m}); });
      for (const Located& s : from) best_[t] = std::min(best_[t], DirectCost(g, cost, s, to[t]));
    }
    std::stable_sort(links_.begin(), links_.end(),
                     [](const Link& a, const Link& b) { return a.node < b.node; });
    Rebound();
  }
  // True once a node settling at `key` can improve no target.
  bool Done(double key) {
    if (!(key > worst_)) return false;
    Rebound();  // worst_ was an upper bound (bests only drop): make it exact
    return key > worst_;
  }
  void Settled(uint32_t u, double cost_u) {
    auto it = std::lower_bound(links_.begin(), links_.end(), u,
                               [](const Link& l, uint32_t n) { return l.node < n; });
    for (; it != links_.end() && it->node == u; ++it) {
      const double c = cost_u + LinkCost(cost_, it->medium, g_.Pos(u), to_[it->target].pos);
      double& best = best_[it->target];
      if (!(c < best)) continue;
      const bool last = best == kInf && --unreached_ == 0;
      best = c;
      if (last) Rebound();  // every target has a best: worst_ becomes finite
    }
  }

 private:
  struct Link {
    uint32_t node, target;
    Medium medium;
  };
  void Rebound() {
    worst_ = -kInf;
    unreached_ = 0;
    for (const double b : best_) {
      worst_ = std::max(worst_, b);
      unreached_ += b == kInf;
    }
  }

  const SteinerGraph& g_;
  const Cost& cost_;
  const std::vector<Located>& to_;
  std::vector<Link> links_;  // what the straight link from each node to each target runs in
  std::vector<double> best_;
  double worst_ = kInf;     // at least the largest best
  uint32_t unreached_ = 0;  // targets with no best yet (worst_ is +inf while there are)
};

PathPoint NodePoint(const SteinerGraph& g, uint32_t n) {
  const TriangleMesh& mesh = g.mesh();
  PathPoint pp;
  const Vec p = g.Pos(n);
  for (int k = 0; k < 3; ++k) pp.position[k] = p[k] + mesh.Center()[k];
  if (n < g.nv()) {
    pp.where = SurfacePoint::AtVertex(mesh.FileVertex(n));
  } else {
    const uint32_t h = g.EdgeHalf(g.EdgeOfNode(n));
    pp.where =
        CanonicalEdgePoint(mesh.FileVertex(mesh.From(h)), mesh.FileVertex(mesh.To(h)), g.Param(n));
  }
  return pp;
}

PathPoint LocatedPoint(const TriangleMesh& mesh, const Located& l) {
  PathPoint pp;
  for (int k = 0; k < 3; ++k) pp.position[k] = l.pos[k] + mesh.Center()[k];
  pp.where = l.canonical;
  return pp;
}

// Seeds every source (its label: its index) and searches to the end, or to max_distance (costs
// beyond it become unreachable): what a field and point costs need.
template <typename Cost>
absl::Status SearchWhole(const std::vector<Located>& sources, const WeightedOptions& options,
                         Search<Cost>* search) {
  for (uint32_t i = 0; i < sources.size(); ++i) search->Seed(sources[i], i);
  absl::Status status = search->Run(
      options, [](double) { return false; }, [](uint32_t) {});
  if (status.ok() && options.check_optimality) status = search->CheckOptimality();
  if (status.ok()) search->ClampTo(options.max_distance);
  return status;
}

}  // namespace

// The graph and its cost model, built once; the cost model refers to the graph and the graph to
// the options' weights, so all three live here, at fixed addresses.
struct WeightedSurface::Impl {
  Impl(const TriangleMesh& mesh, WeightedOptions opts)
      : options(std::move(opts)), graph(mesh, options) {}
  WeightedOptions options;
  SteinerGraph graph;
  std::optional<IsotropicCost> isotropic;
  std::optional<DirectionalCost> directional;
  // The bounded placement's anchors (sorted positions): a search from or to any other point
  // strictly inside a face or an edge needs a surface refined around it (Anchors).
  std::vector<Vec> anchored;
  // Set: one weight, the exact engine answers (OnRegions) and the graph stays unbuilt.
  std::shared_ptr<const RegionSurface> regions;

  // The weights it was built with: the options', or, OnRegions, the region surface's.
  const std::vector<double>& Weights() const {
    return regions != nullptr ? regions->face_weight() : options.face_weight;
  }

  // Whether every point of `points` is a vertex or one of the anchors (or the placement has none).
  bool Anchors(const std::vector<Located>& points) const {
    if (isotropic == std::nullopt) return true;
    for (const Located& l : points) {
      if (l.canonical.kind != SurfacePoint::Kind::kVertex &&
          !std::binary_search(anchored.begin(), anchored.end(), l.pos)) {
        return false;
      }
    }
    return true;
  }

  // Calls fn(cost model).
  template <typename Fn>
  auto WithCost(Fn&& fn) const {
    return isotropic.has_value() ? fn(*isotropic) : fn(*directional);
  }
};

namespace {

// The graph and the cost model of `options` (already validated): the one place the model is
// chosen. Every solve builds its surface here; `seeds` are the sources when known, `anchors` every
// point the surface will be searched from or to (the bounded placement is refined around them).
absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> BuildSurface(
    const TriangleMesh& mesh, const WeightedOptions& options, const std::vector<Located>& seeds,
    const std::vector<Located>& anchors) {
  auto impl = std::make_unique<WeightedSurface::Impl>(mesh, options);
  // The placement goes with the cost model: a model that crosses between points (no bound to
  // keep, kInterpolates) takes them evenly spaced.
  auto placement_of = [](auto interpolates) {
    return interpolates ? SteinerGraph::Placement::kUniform : SteinerGraph::Placement::kBounded;
  };
  const SteinerGraph::Placement placement = options.slope_cost == nullptr
                                                ? placement_of(IsotropicCost::kInterpolates)
                                                : placement_of(DirectionalCost::kInterpolates);
  std::vector<Vec> seed_positions;
  for (const Located& l : seeds) seed_positions.push_back(l.pos);
  if (absl::Status s = impl->graph.Build(options.epsilon, options.max_steiner_points, placement,
                                         seed_positions, anchors);
      !s.ok()) {
    return s;
  }
  if (placement == SteinerGraph::Placement::kBounded) {
    for (const Located& l : anchors) impl->anchored.push_back(l.pos);
    std::sort(impl->anchored.begin(), impl->anchored.end());
  }
  if (options.slope_cost == nullptr) {
    impl->isotropic.emplace(impl->graph);
  } else {
    impl->directional.emplace(impl->graph, *impl->options.slope_cost, options.inbound);
  }
  return impl;
}

// The surface to search from `from` to `to` on: `surface` itself when every point of both (of
// `from` only, without `anchor_targets`) is a vertex or one of its anchors; else one refined
// around them, built for this call and kept in *refined.
absl::StatusOr<const WeightedSurface::Impl*> SurfaceFor(
    const WeightedSurface::Impl& surface, const std::vector<Located>& from,
    const std::vector<Located>& to, bool anchor_targets,
    std::unique_ptr<WeightedSurface::Impl>* refined) {
  if (surface.Anchors(from) && (!anchor_targets || surface.Anchors(to))) return &surface;
  std::vector<Located> anchors = from;
  if (anchor_targets) anchors.insert(anchors.end(), to.begin(), to.end());
  absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> built =
      BuildSurface(surface.graph.mesh(), surface.options, from, anchors);
  if (!built.ok()) return built.status();
  *refined = std::move(*built);
  return refined->get();
}

}  // namespace

absl::Status ValidateWeightedOptions(const TriangleMesh& mesh, const WeightedOptions& options) {
  if (!(options.epsilon > 0 && options.epsilon < 1)) {
    return OptionError("epsilon", absl::StrFormat("must be in (0, 1), got %g", options.epsilon));
  }
  if (!(options.max_distance > 0)) {
    return OptionError("max_distance",
                       absl::StrFormat("must be > 0, got %g", options.max_distance));
  }
  if (options.slope_cost != nullptr) {
    const std::vector<double>& c = options.slope_cost->per_metre;
    bool ok = c.size() >= 2;
    for (size_t i = 0; ok && i < c.size(); ++i) ok = c[i] > 0;  // also NaN
    // The level direction (sine 0) must be walkable: a face always has one.
    if (ok && c.size() % 2 == 1) ok = std::isfinite(c[c.size() / 2]);
    if (ok && c.size() % 2 == 0) ok = std::isfinite(c[c.size() / 2 - 1] + c[c.size() / 2]);
    if (!ok) {
      return OptionError("slope_cost", "needs >= 2 samples, each > 0 (or +inf), finite at slope 0");
    }
  }
  const std::vector<double>& w = options.face_weight;
  if (!w.empty() && w.size() != mesh.face_count()) {
    return OptionError("face_weight", absl::StrFormat("must have one weight per face (%d), got %d",
                                                      mesh.face_count(), w.size()));
  }
  for (size_t f = 0; f < w.size(); ++f) {
    if (!(w[f] > 0)) {  // also NaN
      return OptionError(absl::StrFormat("face_weight[%d]", f),
                         absl::StrFormat("must be > 0 (or +inf: impassable), got %g", w[f]));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<WeightedField> ComputeWeightedField(const TriangleMesh& mesh,
                                                   const std::vector<SurfacePoint>& sources,
                                                   const WeightedOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = ValidateWeightedOptions(mesh, options); !s.ok()) return s;
  if (sources.empty()) return absl::InvalidArgumentError("no sources given");
  std::vector<Located> located;
  if (absl::Status s = Prepare(mesh, sources, &located); !s.ok()) return s;
  absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> surface =
      BuildSurface(mesh, options, located, located);
  if (!surface.ok()) return surface.status();
  const SteinerGraph& g = (*surface)->graph;
  return (*surface)->WithCost([&](const auto& cost) -> absl::StatusOr<WeightedField> {
    Search search(g, cost);
    if (absl::Status s = SearchWhole(located, options, &search); !s.ok()) return s;
    WeightedField field;
    field.cost.assign(mesh.file_vertex_count(), kInf);
    field.source.assign(mesh.file_vertex_count(), kNoIndex);
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      const uint32_t fv = mesh.FileVertex(v);
      if (search.cost(v) < field.cost[fv]) {
        field.cost[fv] = search.cost(v);
        field.source[fv] = search.label(v);
      }
    }
    field.steiner_points = g.steiner_points();
    field.graph_edges = g.graph_edges();
    field.epsilon = options.epsilon;
    field.stats = search.Stats(Elapsed(start));
    return field;
  });
}

WeightedSurface::WeightedSurface(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WeightedSurface::WeightedSurface(WeightedSurface&&) noexcept = default;
WeightedSurface& WeightedSurface::operator=(WeightedSurface&&) noexcept = default;
WeightedSurface::~WeightedSurface() = default;

absl::StatusOr<WeightedSurface> WeightedSurface::Build(const TriangleMesh& mesh,
                                                       const WeightedOptions& options,
                                                       const std::vector<SurfacePoint>& seeds,
                                                       const std::vector<SurfacePoint>& anchors) {
  if (absl::Status s = ValidateWeightedOptions(mesh, options); !s.ok()) return s;
  std::vector<Located> located, anchored;
  if (absl::Status s = Prepare(mesh, seeds, &located); !s.ok()) return s;
  if (absl::Status s = Prepare(mesh, anchors, &anchored); !s.ok()) return s;
  anchored.insert(anchored.end(), located.begin(), located.end());
  absl::StatusOr<std::unique_ptr<Impl>> impl = BuildSurface(mesh, options, located, anchored);
  if (!impl.ok()) return impl.status();
  return WeightedSurface(*std::move(impl));
}

WeightedSurface WeightedSurface::OnRegions(const TriangleMesh& mesh, WeightedOptions options,
                                           std::shared_ptr<const RegionSurface> regions) {
  // The weights stay in `regions` only (Impl::Weights): the unbuilt graph never reads them.
  std::vector<double>().swap(options.face_weight);
  auto impl = std::make_unique<Impl>(mesh, std::move(options));
  impl->regions = std::move(regions);
  return WeightedSurface(std::move(impl));
}

uint64_t WeightedSurface::steiner_points() const {
  return impl_->regions != nullptr ? 0 : impl_->graph.steiner_points();
}

uint64_t WeightedSurface::bytes() const {
  // (the graph reads the options' weights; a surface OnRegions keeps them in `regions`)
  return sizeof(Impl) + impl_->graph.bytes() +
         impl_->options.face_weight.capacity() * sizeof(double) +
         (impl_->regions != nullptr ? impl_->regions->bytes() : 0);
}

const TriangleMesh& WeightedSurface::mesh() const { return impl_->graph.mesh(); }

bool WeightedSurface::Serves(const TriangleMesh& mesh, const WeightedOptions& options) const {
  const WeightedOptions& built = impl_->options;
  return &impl_->graph.mesh() == &mesh && options.slope_cost == nullptr &&
         built.slope_cost == nullptr && options.epsilon == built.epsilon &&
         options.face_weight == impl_->Weights() &&
         (options.max_steiner_points == 0 || steiner_points() <= options.max_steiner_points) &&
         (impl_->regions == nullptr || options.max_windows == built.max_windows);
}

bool WeightedSurface::ServesAnyPoint() const { return impl_->regions != nullptr; }

namespace {

// What a search on a shared surface reads of its options: the query's limits (the surface holds
// the rest), without copying the surface's weights.
WeightedOptions SearchOptions(const WeightedOptions& built, const WeightedSurface::Limits& limits) {
  WeightedOptions out;
  out.epsilon = built.epsilon;
  out.max_distance = limits.max_distance;
  out.cancel = limits.cancel;
  out.check_optimality = built.check_optimality;
  return out;
}

}  // namespace

namespace {
absl::StatusOr<WeightedCosts> CostsOn(const WeightedSurface::Impl& surface,
                                      const std::vector<Located>& from,
                                      const std::vector<Located>& to, bool whole,
                                      const WeightedOptions& options,
                                      std::chrono::steady_clock::time_point start);
}  // namespace

absl::StatusOr<WeightedCosts> WeightedSurface::CostsAt(const std::vector<SurfacePoint>& sources,
                                                       const std::vector<SurfacePoint>& targets,
                                                       bool whole) const {
  return CostsAt(sources, targets, whole, {impl_->options.max_distance, impl_->options.cancel});
}

absl::StatusOr<WeightedCosts> WeightedSurface::CostsAt(const std::vector<SurfacePoint>& sources,
                                                       const std::vector<SurfacePoint>& targets,
                                                       bool whole, const Limits& limits) const {
  if (impl_->regions != nullptr) return impl_->regions->CostsAt(sources, targets, whole, limits);
  const auto start = std::chrono::steady_clock::now();
  if (sources.empty()) return absl::InvalidArgumentError("no sources given");
  if (!(limits.max_distance > 0)) {
    return OptionError("max_distance", absl::StrFormat("must be > 0, got %g", limits.max_distance));
  }
  const WeightedOptions options = SearchOptions(impl_->options, limits);
  std::vector<Located> from, to;
  if (absl::Status s = Prepare(impl_->graph.mesh(), sources, &from); !s.ok()) return s;
  if (absl::Status s = Prepare(impl_->graph.mesh(), targets, &to); !s.ok()) return s;
  std::unique_ptr<Impl> refined;
  absl::StatusOr<const Impl*> surface =
      SurfaceFor(*impl_, from, to, limits.anchor_targets, &refined);
  if (!surface.ok()) return surface.status();
  return CostsOn(**surface, from, to, whole, options, start);
}

namespace {

// CostsAt's search on `surface` (refined around every point of `from` and `to`).
absl::StatusOr<WeightedCosts> CostsOn(const WeightedSurface::Impl& surface,
                                      const std::vector<Located>& from,
                                      const std::vector<Located>& to, bool whole,
                                      const WeightedOptions& options,
                                      std::chrono::steady_clock::time_point start) {
  const SteinerGraph& g = surface.graph;
  return surface.WithCost([&](const auto& cost) -> absl::StatusOr<WeightedCosts> {
    // The answers off a finished search.
    auto answer = [&](const auto& search) {
      WeightedCosts out;
      out.cost.assign(to.size(), kInf);
      out.source.assign(to.size(), kNoIndex);
      for (size_t t = 0; t < to.size(); ++t) {
        const auto [c, n] = BestLink(g, cost, search, to[t]);
        if (n != kNoIndex) {
          out.cost[t] = c;
          out.source[t] = search.label(n);
        }
        for (uint32_t s = 0; s < from.size(); ++s) {
          const double direct = DirectCost(g, cost, from[s], to[t]);
          if (direct < out.cost[t]) {
            out.cost[t] = direct;
            out.source[t] = s;
          }
        }
        if (out.cost[t] > options.max_distance) {
          out.cost[t] = kInf;
          out.source[t] = kNoIndex;
        }
      }
      out.steiner_points = g.steiner_points();
      out.stats = search.Stats(Elapsed(start));
      return out;
    };
    using CostModel = std::decay_t<decltype(cost)>;
    if (whole || options.check_optimality) {
      Search<CostModel> search(g, cost);
      if (absl::Status s = SearchWhole(from, options, &search); !s.ok()) return s;
      return answer(search);
    }
    // Headed for the targets (A*), stopping once each is final.
    Search<CostModel, true> search(g, cost);
    search.HeadFor(GoalOf(g, cost, to));
    TargetWatch watch(g, cost, from, to);
    for (uint32_t i = 0; i < from.size(); ++i) search.Seed(from[i], i);
    absl::Status s = search.Run(
        options, [&](double key) { return watch.Done(key); },
        [&](uint32_t u) { watch.Settled(u, search.cost(u)); });
    if (!s.ok()) return s;
    return answer(search);
  });
}

}  // namespace

absl::StatusOr<WeightedCosts> ComputeWeightedCostsAt(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const WeightedOptions& options) {
  absl::StatusOr<WeightedSurface> surface = WeightedSurface::Build(mesh, options, sources, targets);
  if (!surface.ok()) return surface.status();
  return surface->CostsAt(sources, targets);
}

namespace {

// The paths from src to every dst on a surface built outward; `options`: the query's limits.
absl::StatusOr<std::vector<WeightedPath>> PathsOn(const WeightedSurface::Impl& surface,
                                                  const Located& src,
                                                  const std::vector<Located>& dsts,
                                                  const WeightedOptions& options,
                                                  std::chrono::steady_clock::time_point start) {
  const SteinerGraph& g = surface.graph;
  const TriangleMesh& mesh = g.mesh();
  const std::vector<Located> src_list = {src};
  return surface.WithCost([&](const auto& cost) -> absl::StatusOr<std::vector<WeightedPath>> {
    Search<std::decay_t<decltype(cost)>, true> search(g, cost);
    search.HeadFor(GoalOf(g, cost, dsts));
    search.Seed(src, 0);
    TargetWatch watch(g, cost, src_list, dsts);
    if (absl::Status s = search.Run(
            options, [&](double key) { return watch.Done(key); },
            [&](uint32_t u) { watch.Settled(u, search.cost(u)); });
        !s.ok()) {
      return s;
    }
    std::vector<WeightedPath> paths(dsts.size());
    for (size_t t = 0; t < dsts.size(); ++t) {
      const Located& dst = dsts[t];
      WeightedPath& path = paths[t];
      path.steiner_points = g.steiner_points();
      auto [total, node] = BestLink(g, cost, search, dst);
      const double direct = DirectCost(g, cost, src, dst);
      if (direct <= total) {
        total = direct;
        node = kNoIndex;
      }
      if (!std::isfinite(total) || total > options.max_distance) {
        path.cost = kInf;  // unreachable: no points
        continue;
      }
      path.cost = total;
      // Backwards from the target, then reversed.
      path.points.push_back(LocatedPoint(mesh, dst));
      uint32_t parent = kFromSourcePoint;
      while (node != kNoIndex) {
        if (!(dst.canonical.kind == SurfacePoint::Kind::kVertex && search.cost(node) == total &&
              path.points.size() == 1 && node < g.nv() &&
              mesh.FileVertex(node) == dst.canonical.vertex)) {
          path.points.push_back(NodePoint(g, node));
        }
        parent = search.parent(node);
        node = parent >= kFromSourcePoint ? kNoIndex : parent;
      }
      if (parent == kFromSourcePoint) path.points.push_back(LocatedPoint(mesh, src));
      std::reverse(path.points.begin(), path.points.end());
    }
    const WeightedStats stats = search.Stats(Elapsed(start));
    for (WeightedPath& path : paths) path.stats = stats;
    return paths;
  });
}

}  // namespace

absl::StatusOr<std::vector<WeightedPath>> ComputeWeightedPaths(const TriangleMesh& mesh,
                                                               const SurfacePoint& from,
                                                               const std::vector<SurfacePoint>& tos,
                                                               const WeightedOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = ValidateWeightedOptions(mesh, options); !s.ok()) return s;
  std::vector<Located> src_list, dsts;
  if (absl::Status s = Prepare(mesh, {from}, &src_list); !s.ok()) return s;
  if (absl::Status s = Prepare(mesh, tos, &dsts); !s.ok()) return s;
  // A path is walked from `from`: the search runs outward whatever options.inbound says. One graph
  // and one search serve every target; it stops once every target's best is final.
  WeightedOptions outward = options;
  outward.inbound = false;
  std::vector<Located> anchors = src_list;
  anchors.insert(anchors.end(), dsts.begin(), dsts.end());
  absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> surface =
      BuildSurface(mesh, outward, src_list, anchors);
  if (!surface.ok()) return surface.status();
  return PathsOn(**surface, src_list[0], dsts, options, start);
}

absl::StatusOr<std::vector<WeightedPath>> WeightedSurface::Paths(
    const SurfacePoint& from, const std::vector<SurfacePoint>& tos, const Limits& limits) const {
  if (impl_->regions != nullptr) return impl_->regions->Paths(from, tos, limits);
  const auto start = std::chrono::steady_clock::now();
  if (impl_->options.inbound && impl_->options.slope_cost != nullptr) {
    return OptionError("inbound", "a path is walked from its start: build the surface outward");
  }
  if (!(limits.max_distance > 0)) {
    return OptionError("max_distance", absl::StrFormat("must be > 0, got %g", limits.max_distance));
  }
  std::vector<Located> src_list, dsts;
  if (absl::Status s = Prepare(impl_->graph.mesh(), {from}, &src_list); !s.ok()) return s;
  if (absl::Status s = Prepare(impl_->graph.mesh(), tos, &dsts); !s.ok()) return s;
  const WeightedOptions options = SearchOptions(impl_->options, limits);
  std::unique_ptr<Impl> refined;
  absl::StatusOr<const Impl*> surface =
      SurfaceFor(*impl_, src_list, dsts, /*anchor_targets=*/true, &refined);
  if (!surface.ok()) return surface.status();
  return PathsOn(**surface, src_list[0], dsts, options, start);
}

absl::StatusOr<WeightedPath> ComputeWeightedPath(const TriangleMesh& mesh, const SurfacePoint& from,
                                                 const SurfacePoint& to,
                                                 const WeightedOptions& options) {
  absl::StatusOr<std::vector<WeightedPath>> paths = ComputeWeightedPaths(mesh, from, {to}, options);
  if (!paths.ok()) return paths.status();
  WeightedPath& path = (*paths)[0];
  if (!std::isfinite(path.cost)) {
    return absl::NotFoundError(
        absl::StrFormat("point %s cannot be reached from %s%s", SurfacePointToString(to),
                        SurfacePointToString(from),
                        std::isfinite(options.max_distance) ? " within max_distance" : ""));
  }
  return std::move(path);
}

}  // namespace geodex

namespace geodex {

absl::StatusOr<RegionBoundaryPoints> PlaceRegionBoundaryPoints(
    const TriangleMesh& mesh, const WeightedOptions& options,
    const std::vector<SurfacePoint>& anchors) {
  const uint32_t nh = 3 * mesh.face_count();
  std::vector<uint8_t> marked(nh, 0);
  auto weight = [&](uint32_t f) {
    return options.face_weight.empty() ? 1.0 : options.face_weight[f];
  };
  for (uint32_t h = 0; h < nh; ++h) {
    const uint32_t t = mesh.Twin(h);
    if (t == kNoIndex || t < h) continue;
    const double a = weight(TriangleMesh::FaceOf(h)), b = weight(TriangleMesh::FaceOf(t));
    if (std::isfinite(a) && std::isfinite(b) && a != b) marked[h] = 1;
  }
  RegionBoundaryPoints out;
  if (std::find(marked.begin(), marked.end(), 1) == marked.end()) {
    out.first.push_back(0);  // one weight: no boundary (the anchors are checked where mapped)
    return out;
  }
  std::vector<Located> located;
  if (absl::Status s = Prepare(mesh, anchors, &located); !s.ok()) return s;
  SteinerGraph graph(mesh, options);
  graph.PlaceOnlyOn(std::move(marked));
  if (absl::Status s = graph.Build(options.epsilon, options.max_steiner_points,
                                   SteinerGraph::Placement::kBounded, {}, located);
      !s.ok()) {
    return s;
  }
  for (uint32_t e = 0; e < graph.edge_count(); ++e) {
    if (!graph.Placed(e) || graph.First(e) == graph.End(e)) continue;
    out.half_edge.push_back(graph.EdgeHalf(e));
    out.first.push_back(static_cast<uint32_t>(out.param.size()));
    for (uint32_t n = graph.First(e); n < graph.End(e); ++n) out.param.push_back(graph.Param(n));
  }
  out.first.push_back(static_cast<uint32_t>(out.param.size()));
  return out;
}

}  // namespace geodex
