// The incremental Delaunay triangulation (terrain/src/delaunay_2d.h): after every batch of
// insertions the structure is checked whole (counter-clockwise triangles, symmetric neighbours,
// the empty-circle property on every interior edge with the exact predicate, Euler's count, the
// rectangle's area); on random points in general position the triangles are GEOS's; on grids, where
// many triangulations are Delaunay, only the property is checked.

#include "delaunay_2d.h"

#include <geos_c.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "gtest/gtest.h"
#include "robust_predicates.h"

namespace geodex::terrain {
namespace {

using Point = Delaunay2d::Point;
constexpr uint32_t kNone = Delaunay2d::kNone;

int Next(int k) { return (k + 1) % 3; }
int Previous(int k) { return (k + 2) % 3; }

bool OnBoundary(const Delaunay2d& dt, const Point& p) {
  const Point &low = dt.point(0), &high = dt.point(2);
  return p[0] == low[0] || p[0] == high[0] || p[1] == low[1] || p[1] == high[1];
}

// Everything a Delaunay triangulation of the rectangle must be. `global`: also check every
// vertex against every triangle's circle (quadratic; small inputs).
void CheckTriangulation(const Delaunay2d& dt, bool global = false) {
  const uint32_t n = dt.vertex_count(), triangles = dt.triangle_count();
  uint32_t hull = 0;
  for (uint32_t v = 0; v < n; ++v) hull += OnBoundary(dt, dt.point(v));
  ASSERT_EQ(triangles, 2 * n - 2 - hull) << "Euler: faces = 2n - 2 - h";

  const Point &low = dt.point(0), &high = dt.point(2);
  double area = 0;
  std::vector<int> uses(n, 0);
  for (uint32_t t = 0; t < triangles; ++t) {
    const auto& c = dt.corners(t);
    for (uint32_t v : c) ASSERT_LT(v, n);
    for (uint32_t v : c) ++uses[v];
    const Point &a = dt.point(c[0]), &b = dt.point(c[1]), &d = dt.point(c[2]);
    ASSERT_GT(Orient2d(a, b, d), 0) << "triangle " << t << " is not counter-clockwise";
    area += 0.5 * ((b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]));
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = dt.neighbours(t)[k];
      const uint32_t e0 = c[Next(k)], e1 = c[Previous(k)];
      if (u == kNone) {
        // A boundary edge: both ends on the same side of the rectangle.
        const Point &p = dt.point(e0), &q = dt.point(e1);
        ASSERT_TRUE((p[0] == q[0] && (p[0] == low[0] || p[0] == high[0])) ||
                    (p[1] == q[1] && (p[1] == low[1] || p[1] == high[1])))
            << "triangle " << t << " has no neighbour across an inner edge";
        continue;
      }
      ASSERT_LT(u, triangles);
      int j = 0;
      while (j < 3 && dt.neighbours(u)[j] != t) ++j;
      ASSERT_LT(j, 3) << "neighbours not symmetric: " << t << " " << u;
      ASSERT_EQ(dt.corners(u)[Next(j)], e1);
      ASSERT_EQ(dt.corners(u)[Previous(j)], e0);
      // Empty circle, exactly: the vertex across the edge is not strictly inside.
      const Point& q = dt.point(dt.corners(u)[j]);
      ASSERT_LE(InCircle(a, b, d, q), 0) << "edge " << e0 << "-" << e1 << " is not Delaunay";
    }
  }
  for (uint32_t v = 0; v < n; ++v) ASSERT_GT(uses[v], 0) << "vertex " << v << " is in no triangle";
  const double rectangle = (high[0] - low[0]) * (high[1] - low[1]);
  EXPECT_NEAR(area, rectangle, 1e-12 * rectangle);

  if (global) {
    for (uint32_t t = 0; t < triangles; ++t) {
      const auto& c = dt.corners(t);
      for (uint32_t v = 0; v < n; ++v) {
        ASSERT_LE(InCircle(dt.point(c[0]), dt.point(c[1]), dt.point(c[2]), dt.point(v)), 0)
            << "vertex " << v << " inside the circle of triangle " << t;
      }
    }
  }
}

TEST(Delaunay2dTest, StartsAsTheRectangle) {
  Delaunay2d dt(-1, 2, 5, 3);
  EXPECT_EQ(dt.vertex_count(), 4u);
  EXPECT_EQ(dt.triangle_count(), 2u);
  CheckTriangulation(dt, true);
}

TEST(Delaunay2dTest, RandomPoints) {
  for (const uint64_t seed : {1u, 2u, 3u}) {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> x(0, 100), y(-20, 30);
    Delaunay2d dt(0, -20, 100, 30);
    std::vector<uint32_t> changed;
    for (int i = 0; i < 3000; ++i) {
      const Point p{x(random), y(random)};
      changed.clear();
      const uint32_t v = dt.Insert(p, Delaunay2d::kNone, &changed);
      ASSERT_EQ(v, static_cast<uint32_t>(i + 4));
      ASSERT_EQ(dt.point(v), p);
      ASSERT_GE(changed.size(), 3u);
      for (uint32_t t : changed) ASSERT_LT(t, dt.triangle_count());
      if (i == 50) CheckTriangulation(dt, true);
    }
    CheckTriangulation(dt);
  }
}

TEST(Delaunay2dTest, ChangedListsEveryTriangleThatChanged) {
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> unit(0, 1);
  Delaunay2d dt(0, 0, 1, 1);
  for (int i = 0; i < 400; ++i) {
    std::vector<std::array<uint32_t, 6>> before;
    for (uint32_t t = 0; t < dt.triangle_count(); ++t) {
      const auto &c = dt.corners(t), &n = dt.neighbours(t);
      before.push_back({c[0], c[1], c[2], n[0], n[1], n[2]});
    }
    std::vector<uint32_t> changed;
    // Every third point on the boundary or a grid line, to split edges too.
    Point p{unit(random), unit(random)};
    if (i % 3 == 0) p[i % 2] = std::round(p[i % 2] * 4) / 4;
    dt.Insert(p, Delaunay2d::kNone, &changed);
    const std::set<uint32_t> listed(changed.begin(), changed.end());
    for (uint32_t t = 0; t < before.size(); ++t) {
      // Only corners count: a neighbour id changes when the triangle next door is split.
      const bool same =
          std::array<uint32_t, 3>{before[t][0], before[t][1], before[t][2]} == dt.corners(t);
      if (!same) {
        ASSERT_TRUE(listed.count(t)) << "triangle " << t << " changed, not listed";
      }
    }
    for (uint32_t t = before.size(); t < dt.triangle_count(); ++t) ASSERT_TRUE(listed.count(t));
  }
  CheckTriangulation(dt, true);
}

// A raster's cell centres in several insertion orders: all cocircular squares.
TEST(Delaunay2dTest, GridsInAnyOrder) {
  const int columns = 24, rows = 17;
  std::vector<Point> grid;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) grid.push_back({double(c), double(r)});
  }
  std::vector<std::vector<Point>> orders;
  orders.push_back(grid);                          // row by row
  orders.push_back({grid.rbegin(), grid.rend()});  // backwards
  for (const uint64_t seed : {1u, 2u, 3u, 4u}) {   // shuffled
    std::vector<Point> shuffled = grid;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(seed));
    orders.push_back(shuffled);
  }
  std::vector<Point> coarse_to_fine;  // every 8th, then every 4th, ... as a TIN refines
  for (int step : {8, 4, 2, 1}) {
    for (const Point& p : grid) {
      if (int(p[0]) % step == 0 && int(p[1]) % step == 0) coarse_to_fine.push_back(p);
    }
  }
  orders.push_back(coarse_to_fine);

  for (size_t o = 0; o < orders.size(); ++o) {
    SCOPED_TRACE(o);
    Delaunay2d dt(0, 0, columns - 1, rows - 1);
    for (const Point& p : orders[o]) {
      const uint32_t v = dt.Insert(p);
      ASSERT_NE(v, Delaunay2d::kNone);
      ASSERT_EQ(dt.point(v), p);
    }
    EXPECT_EQ(dt.vertex_count(), uint32_t(rows * columns));
    CheckTriangulation(dt, o == 0);
    // Every triangle of a Delaunay triangulation of a unit grid is half a cell.
    for (uint32_t t = 0; t < dt.triangle_count(); ++t) {
      const auto& c = dt.corners(t);
      EXPECT_EQ(Orient2d(dt.point(c[0]), dt.point(c[1]), dt.point(c[2])), 1.0);
    }
  }
}

TEST(Delaunay2dTest, DuplicatesBoundaryAndOutsidePoints) {
  Delaunay2d dt(0, 0, 10, 10);
  EXPECT_EQ(dt.Insert({10, 10}), 2u);  // a corner
  const uint32_t v = dt.Insert({5, 5});
  EXPECT_EQ(dt.Insert({5, 5}), v);
  std::vector<uint32_t> changed;
  EXPECT_EQ(dt.Insert({5, 5}, Delaunay2d::kNone, &changed), v);
  EXPECT_TRUE(changed.empty());
  EXPECT_EQ(dt.Insert({10.5, 5}), Delaunay2d::kNone);
  EXPECT_EQ(dt.Insert({5, -1e-300}), Delaunay2d::kNone);
  EXPECT_EQ(dt.Insert({NAN, 5}), Delaunay2d::kNone);
  EXPECT_EQ(dt.vertex_count(), 5u);
  // Points on each side of the rectangle and on inner edges.
  for (const Point& p : std::vector<Point>{
           {0, 3}, {10, 7}, {4, 0}, {6, 10}, {0, 6}, {2.5, 2.5}, {7.5, 7.5}, {0, 1.5}, {3, 0}}) {
    EXPECT_NE(dt.Insert(p), Delaunay2d::kNone);
    CheckTriangulation(dt, true);
  }
  EXPECT_EQ(dt.vertex_count(), 14u);
}

// Near-degenerate input far from the origin: points rounded off a circle, and collinear runs.
TEST(Delaunay2dTest, NearlyCocircularAndCollinearFarFromTheOrigin) {
  const double x0 = 1e6, y0 = 2e6;
  Delaunay2d dt(x0, y0, x0 + 4, y0 + 4);
  for (int i = 0; i < 200; ++i) {
    const double angle = 2 * M_PI * i / 200;
    ASSERT_NE(dt.Insert({x0 + 2 + 1.5 * std::cos(angle), y0 + 2 + 1.5 * std::sin(angle)}), kNone);
  }
  for (int i = 1; i < 40; ++i) ASSERT_NE(dt.Insert({x0 + 0.1 * i, y0 + 0.1 * i}), kNone);
  ASSERT_NE(dt.Insert({x0 + 2, y0 + 2}), kNone);
  CheckTriangulation(dt, true);
}

// GEOS's triangulation of the same points (the 4 corners and the random ones) as sorted triples
// of points.
std::set<std::array<Point, 3>> GeosTriangles(const std::vector<Point>& points) {
  GEOSContextHandle_t h = GEOS_init_r();
  std::vector<GEOSGeometry*> geometries;
  for (const Point& p : points) geometries.push_back(GEOSGeom_createPointFromXY_r(h, p[0], p[1]));
  GEOSGeometry* multipoint = GEOSGeom_createCollection_r(h, GEOS_MULTIPOINT, geometries.data(),
                                                         static_cast<unsigned>(geometries.size()));
  GEOSGeometry* triangulation = GEOSDelaunayTriangulation_r(h, multipoint, 0.0, 0);
  std::set<std::array<Point, 3>> triangles;
  for (int i = 0; i < GEOSGetNumGeometries_r(h, triangulation); ++i) {
    const GEOSGeometry* ring = GEOSGetExteriorRing_r(h, GEOSGetGeometryN_r(h, triangulation, i));
    const GEOSCoordSequence* sequence = GEOSGeom_getCoordSeq_r(h, ring);
    std::array<Point, 3> triangle;
    for (unsigned k = 0; k < 3; ++k) {
      GEOSCoordSeq_getXY_r(h, sequence, k, &triangle[k][0], &triangle[k][1]);
    }
    std::sort(triangle.begin(), triangle.end());
    triangles.insert(triangle);
  }
  GEOSGeom_destroy_r(h, triangulation);
  GEOSGeom_destroy_r(h, multipoint);
  GEOS_finish_r(h);
  return triangles;
}

TEST(Delaunay2dTest, SameTrianglesAsGeosOnRandomPoints) {
  for (const uint64_t seed : {10u, 11u}) {
    std::mt19937_64 random(seed);
    // Away from the rectangle's sides: GEOS (3.11) leaves out some of the thin triangles along
    // the hull when points come within a few thousandths of it (ours are there: the check above
    // covers them).
    std::uniform_real_distribution<double> x(-2.5, 6.5), y(100.5, 103.5);
    Delaunay2d dt(-3, 100, 7, 104);
    for (int i = 0; i < 1500; ++i) dt.Insert({x(random), y(random)});
    CheckTriangulation(dt);
    std::vector<Point> points;
    for (uint32_t v = 0; v < dt.vertex_count(); ++v) points.push_back(dt.point(v));
    std::set<std::array<Point, 3>> ours;
    for (uint32_t t = 0; t < dt.triangle_count(); ++t) {
      std::array<Point, 3> triangle;
      for (int k = 0; k < 3; ++k) triangle[k] = dt.point(dt.corners(t)[k]);
      std::sort(triangle.begin(), triangle.end());
      ours.insert(triangle);
    }
    const std::set<std::array<Point, 3>> geos = GeosTriangles(points);
    EXPECT_EQ(ours.size(), dt.triangle_count());
    EXPECT_EQ(geos.size(), ours.size());
    EXPECT_TRUE(geos == ours) << "seed " << seed;
    size_t shared = 0;
    for (const auto& triangle : geos) shared += ours.count(triangle);
    EXPECT_EQ(shared, geos.size());
  }
}

}  // namespace
}  // namespace geodex::terrain
