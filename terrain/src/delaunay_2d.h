#pragma once

// An incremental Delaunay triangulation of points in an axis-aligned rectangle, for the adaptive
// TIN (adaptive_tin.h): it starts as the rectangle's 4 corners and 2 triangles, and each point
// inserted splits the triangle (or the edge) it falls in, after which Lawson's edge flips restore
// the empty-circle property around it. Decisions use the exact-sign predicates
// (robust_predicates.h), so the result is a true Delaunay triangulation of the exact input points.
//
// Degenerate input is the normal case here (a raster's cell centres: rows of collinear points,
// squares of cocircular ones). An edge is flipped only when the opposite point lies strictly
// inside the circle, so each flip strictly improves the triangulation and the flipping stops;
// among cocircular points the first triangulation found stays (which one depends only on the
// insertion order: the result is deterministic).
//
// Storage is flat: per triangle its 3 vertex ids, counter-clockwise, and its 3 neighbours, the one
// across the edge opposite vertex k in slot k (kNone on the rectangle's boundary). A triangle's id
// never changes meaning: an insertion rewrites the triangles it changes in place and appends new
// ones, never removes any, so a caller may keep per-triangle data in arrays indexed by id.

#include <array>
#include <cstdint>
#include <vector>

namespace geodex::terrain {

class Delaunay2d {
 public:
  static constexpr uint32_t kNone = 0xffffffffu;
  using Point = std::array<double, 2>;

  // The rectangle [x0, x1] x [y0, y1] (x0 < x1, y0 < y1): vertices 0 to 3 are its corners
  // (x0, y0), (x1, y0), (x1, y1), (x0, y1); triangles 0 and 1 split it along the diagonal 0-2.
  Delaunay2d(double x0, double y0, double x1, double y1);

  // Inserts `p` and returns its vertex id. `hint`: a triangle at or near p (kNone: start where the
  // last insertion ended); the search walks from it. Every triangle the insertion created or
  // rewrote is appended to `changed` (when not null; possibly more than once).
  // A point equal to an existing vertex changes nothing and returns that vertex's id; a point
  // outside the rectangle changes nothing and returns kNone.
  uint32_t Insert(const Point& p, uint32_t hint = kNone, std::vector<uint32_t>* changed = nullptr);

  uint32_t vertex_count() const { return static_cast<uint32_t>(points_.size()); }
  uint32_t triangle_count() const { return static_cast<uint32_t>(corners_.size()); }
  const Point& point(uint32_t v) const { return points_[v]; }
  // Counter-clockwise vertex ids.
  const std::array<uint32_t, 3>& corners(uint32_t t) const { return corners_[t]; }
  // neighbours(t)[k]: the triangle across the edge opposite corners(t)[k], or kNone.
  const std::array<uint32_t, 3>& neighbours(uint32_t t) const { return neighbours_[t]; }

 private:
  // Where a point lies: inside triangle `t`, on its edge `edge` (opposite corner `edge`), or on
  // its corner `corner`; or outside the rectangle (t == kNone).
  struct Location {
    uint32_t t = kNone;
    int edge = -1;
    int corner = -1;
  };
  Location Locate(const Point& p, uint32_t start) const;
  Location LocateByScan(const Point& p) const;
  Location Classify(uint32_t t, const Point& p) const;

  uint32_t AddTriangle();
  void SetTriangle(uint32_t t, uint32_t a, uint32_t b, uint32_t c, uint32_t na, uint32_t nb,
                   uint32_t nc);
  // In triangle `t`, the neighbour slot that holds `old` now holds `now`.
  void ReplaceNeighbour(uint32_t t, uint32_t old, uint32_t now);
  // Restores the Delaunay property around new vertex `v`: `stack_` holds triangles with v as
  // corner 0 whose edge opposite v may be illegal.
  void Legalize(uint32_t v, std::vector<uint32_t>* changed);

  std::vector<Point> points_;
  std::vector<std::array<uint32_t, 3>> corners_;
  std::vector<std::array<uint32_t, 3>> neighbours_;
  std::vector<uint32_t> stack_;  // Legalize's work list, kept to save allocations
  uint32_t last_ = 0;            // the triangle the last insertion ended in
};

}  // namespace geodex::terrain
