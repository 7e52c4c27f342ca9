#include "delaunay_2d.h"

#include <cstddef>

#include "robust_predicates.h"

namespace geodex::terrain {
namespace {

int Next(int k) { return k == 2 ? 0 : k + 1; }
int Previous(int k) { return k == 0 ? 2 : k - 1; }

}  // namespace

Delaunay2d::Delaunay2d(double x0, double y0, double x1, double y1) {
  points_ = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  corners_ = {{0, 1, 2}, {0, 2, 3}};
  neighbours_ = {{kNone, 1, kNone}, {kNone, kNone, 0}};
}

uint32_t Delaunay2d::AddTriangle() {
  corners_.push_back({kNone, kNone, kNone});
  neighbours_.push_back({kNone, kNone, kNone});
  return static_cast<uint32_t>(corners_.size() - 1);
}

void Delaunay2d::SetTriangle(uint32_t t, uint32_t a, uint32_t b, uint32_t c, uint32_t na,
                             uint32_t nb, uint32_t nc) {
  corners_[t] = {a, b, c};
  neighbours_[t] = {na, nb, nc};
}

void Delaunay2d::ReplaceNeighbour(uint32_t t, uint32_t old, uint32_t now) {
  if (t == kNone) return;
  for (uint32_t& n : neighbours_[t]) {
    if (n == old) {
      n = now;
      return;
    }
  }
}

Delaunay2d::Location Delaunay2d::Classify(uint32_t t, const Point& p) const {
  const auto& c = corners_[t];
  int zeros = 0, zero[2] = {-1, -1};
  for (int k = 0; k < 3; ++k) {
    const double side = Orient2d(points_[c[Next(k)]], points_[c[Previous(k)]], p);
    if (side < 0) return Location{};
    if (side == 0 && zeros < 2) zero[zeros++] = k;  // a proper triangle has at most 2
  }
  Location at;
  at.t = t;
  if (zeros == 1) at.edge = zero[0];
  if (zeros >= 2) at.corner = 3 - zero[0] - zero[1];  // the corner both edges share
  return at;
}

// A visibility walk: step across any edge that has p strictly on its far side. On a Delaunay
// triangulation this reaches p's triangle whatever edge each step picks (Edelsbrunner: the
// triangles are acyclic in their order of distance to p), so it cannot loop; the step bound and
// the scan behind it are insurance only.
Delaunay2d::Location Delaunay2d::Locate(const Point& p, uint32_t t) const {
  uint32_t came_from = kNone;
  const size_t limit = corners_.size() + 16;
  for (size_t step = 0; step < limit; ++step) {
    const auto& c = corners_[t];
    uint32_t next = kNone;
    for (int k = 0; k < 3; ++k) {
      const uint32_t across = neighbours_[t][k];
      if (across != kNone && across == came_from) continue;  // p is on this side of that edge
      if (Orient2d(points_[c[Next(k)]], points_[c[Previous(k)]], p) < 0) {
        if (across == kNone) return Location{};  // beyond the rectangle's boundary
        next = across;
        break;
      }
    }
    if (next == kNone) return Classify(t, p);
    came_from = t;
    t = next;
  }
  return LocateByScan(p);
}

Delaunay2d::Location Delaunay2d::LocateByScan(const Point& p) const {
  for (uint32_t t = 0; t < triangle_count(); ++t) {
    const Location at = Classify(t, p);
    if (at.t != kNone) return at;
  }
  return Location{};
}

uint32_t Delaunay2d::Insert(const Point& p, uint32_t hint, std::vector<uint32_t>* changed) {
  const Point &low = points_[0], &high = points_[2];
  if (!(p[0] >= low[0] && p[0] <= high[0] && p[1] >= low[1] && p[1] <= high[1])) return kNone;
  const Location at = Locate(p, hint < triangle_count() ? hint : last_);
  if (at.t == kNone) return kNone;
  if (at.corner >= 0) return corners_[at.t][at.corner];

  const uint32_t v = vertex_count();
  points_.push_back(p);
  stack_.clear();
  const uint32_t t = at.t;
  if (at.edge < 0) {
    // Inside t = (a, b, c): three triangles around v, t keeping the one on edge a b.
    const auto [a, b, c] = corners_[t];
    const auto [na, nb, nc] = neighbours_[t];
    const uint32_t t1 = AddTriangle(), t2 = AddTriangle();
    SetTriangle(t, v, a, b, nc, t1, t2);
    SetTriangle(t1, v, b, c, na, t2, t);
    SetTriangle(t2, v, c, a, nb, t, t1);
    ReplaceNeighbour(na, t, t1);
    ReplaceNeighbour(nb, t, t2);
    stack_ = {t, t1, t2};
  } else {
    // On the edge a b of t = (c, a, b) (c opposite the edge), shared with u = (d, b, a) unless
    // the edge is on the boundary: each side is cut in two at v.
    const int k = at.edge;
    const uint32_t c = corners_[t][k], a = corners_[t][Next(k)], b = corners_[t][Previous(k)];
    const uint32_t across_a = neighbours_[t][Next(k)];      // beyond edge b c
    const uint32_t across_b = neighbours_[t][Previous(k)];  // beyond edge c a
    const uint32_t u = neighbours_[t][k];
    const uint32_t t2 = AddTriangle();
    uint32_t u2 = kNone;
    if (u != kNone) {
      int j = 0;
      while (neighbours_[u][j] != t) ++j;
      const uint32_t d = corners_[u][j];
      const uint32_t u_across_b = neighbours_[u][Next(j)];      // beyond edge a d
      const uint32_t u_across_a = neighbours_[u][Previous(j)];  // beyond edge d b
      u2 = AddTriangle();
      SetTriangle(u, v, a, d, u_across_b, u2, t);
      SetTriangle(u2, v, d, b, u_across_a, t2, u);
      ReplaceNeighbour(u_across_a, u, u2);
    }
    SetTriangle(t, v, c, a, across_b, u, t2);
    SetTriangle(t2, v, b, c, across_a, t, u2);
    ReplaceNeighbour(across_a, t, t2);
    stack_ = {t, t2};
    if (u != kNone) stack_.insert(stack_.end(), {u, u2});
  }
  if (changed != nullptr) changed->insert(changed->end(), stack_.begin(), stack_.end());
  Legalize(v, changed);
  last_ = t;  // still has v as a corner: every triangle Legalize rewrites keeps it
  return v;
}

// Lawson's flips around a new vertex: each triangle (v, a, b) on the stack checks the edge a b
// against the vertex q across it; when q lies strictly inside the circle through v, a, b, the
// edge is replaced by v q, and the two new triangles' far edges are checked in turn. Only edges
// opposite v can have become illegal, and each flip strictly reduces the sum of the triangles'
// lifted volumes, so this ends; cocircular quadruples are left as they are.
void Delaunay2d::Legalize(uint32_t v, std::vector<uint32_t>* changed) {
  while (!stack_.empty()) {
    const uint32_t t = stack_.back();
    stack_.pop_back();
    const uint32_t u = neighbours_[t][0];
    if (u == kNone) continue;
    const uint32_t a = corners_[t][1], b = corners_[t][2];
    int j = 0;
    while (neighbours_[u][j] != t) ++j;
    const uint32_t q = corners_[u][j];  // u = (q, b, a)
    if (InCircle(points_[v], points_[a], points_[b], points_[q]) <= 0) continue;

    const uint32_t t_across_a = neighbours_[t][1];            // beyond edge b v
    const uint32_t t_across_b = neighbours_[t][2];            // beyond edge v a
    const uint32_t u_across_b = neighbours_[u][Next(j)];      // beyond edge a q
    const uint32_t u_across_a = neighbours_[u][Previous(j)];  // beyond edge q b
    SetTriangle(t, v, a, q, u_across_b, u, t_across_b);
    SetTriangle(u, v, q, b, u_across_a, t_across_a, t);
    ReplaceNeighbour(u_across_b, u, t);
    ReplaceNeighbour(t_across_a, t, u);
    stack_.push_back(t);
    stack_.push_back(u);
    if (changed != nullptr) changed->insert(changed->end(), {t, u});
  }
}

}  // namespace geodex::terrain
