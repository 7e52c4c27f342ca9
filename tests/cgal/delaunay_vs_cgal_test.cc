// The adaptive TIN's Delaunay triangulation (terrain/src/delaunay_2d.h) against CGAL's
// Delaunay_triangulation_2 (a test-only reference): on points in general position the two
// triangulations are the same triangles.

#include <algorithm>
#include <array>
#include <random>
#include <vector>

#include "delaunay_2d.h"
#include "gtest/gtest.h"
#include "testkit/cgal_reference.h"

namespace geodex {
namespace {

std::vector<std::array<uint32_t, 3>> OursOf(const terrain::Delaunay2d& d) {
  std::vector<std::array<uint32_t, 3>> out;
  for (uint32_t t = 0; t < d.triangle_count(); ++t) {
    std::array<uint32_t, 3> c = d.corners(t);
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(DelaunayVsCgal, RandomPointsGiveCgalsTriangles) {
  for (const uint32_t seed : {1u, 2u, 3u}) {
    std::mt19937 random(seed);
    // Points well inside the rectangle, at coordinates like a raster's (large offsets, cells).
    std::uniform_real_distribution<double> x(600000.5, 629999.5), y(5070000.5, 5099999.5);
    terrain::Delaunay2d ours(600000, 5070000, 630000, 5100000);
    std::vector<std::array<double, 2>> points;
    for (uint32_t v = 0; v < ours.vertex_count(); ++v) points.push_back(ours.point(v));
    for (int k = 0; k < 3000; ++k) {
      const std::array<double, 2> p = {x(random), y(random)};
      ASSERT_EQ(ours.Insert(p), points.size());
      points.push_back(p);
    }
    const std::vector<std::array<uint32_t, 3>> mine = OursOf(ours);
    const std::vector<std::array<uint32_t, 3>> cgal = CgalDelaunayTriangles(points);
    ASSERT_EQ(mine.size(), 2 * points.size() - 2 - 4) << seed;  // Euler: 2n - 2 - hull
    EXPECT_EQ(mine, cgal) << seed;
  }
}

}  // namespace
}  // namespace geodex
