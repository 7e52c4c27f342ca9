// The Steiner points placed (weighted/steiner_graph.h): the bounded placement (dense near
// vertices, refined around anchors) or the uniform one (graded near seeds), the graph's edge
// count, and the points on the regions' boundaries alone (PlaceRegionBoundaryPoints,
// weighted_regions.h).

#include "weighted/steiner_graph.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "geodex/limits.h"
#include "geodex/triangle_mesh.h"
#include "weighted_regions.h"

namespace geodex {

namespace weighted_internal {

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
        absl::StrFormat("epsilon %g needs %d Steiner points on this mesh, more than the %d "
                        "allowed; use a larger epsilon or allow more points",
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

}  // namespace weighted_internal

using weighted_internal::Located;
using weighted_internal::Prepare;
using weighted_internal::SteinerGraph;

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
