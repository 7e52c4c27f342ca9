// The weighted engine's cost models (private to core): what a straight piece in a face or along an
// edge costs, isotropic (weight x length) or directional (a slope cost, with switchbacks), and the
// links a located point makes to the graph's nodes with their costs.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"
#include "weighted/steiner_graph.h"

namespace geodex::weighted_internal {

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

}  // namespace geodex::weighted_internal
