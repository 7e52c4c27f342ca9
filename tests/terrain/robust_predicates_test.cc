// The exact-sign predicates (terrain/src/robust_predicates.h) against an independent exact
// evaluation: every coordinate is a double, so scaled by a power of two it is an integer; the
// determinants of those integers are computed in 256-bit two's-complement arithmetic, which is
// exact for the inputs used here. Inputs are near-degenerate on purpose (points a few ulps off a
// line or a circle, large offsets), where evaluating the same formulas in plain doubles gives
// wrong or zero signs; each test checks that it does, so the test is not an easy one.

#include "robust_predicates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "gtest/gtest.h"

namespace geodex::terrain {
namespace {

using Point2 = std::array<double, 2>;

// A signed integer modulo 2^256 (two's complement): exact while values stay below 2^255.
struct Int256 {
  std::array<uint64_t, 4> w{};

  static Int256 From(__int128 v) {
    Int256 r;
    r.w[0] = static_cast<uint64_t>(v);
    r.w[1] = static_cast<uint64_t>(v >> 64);
    r.w[2] = r.w[3] = v < 0 ? ~uint64_t{0} : 0;
    return r;
  }
  friend Int256 operator+(const Int256& a, const Int256& b) {
    Int256 r;
    unsigned __int128 carry = 0;
    for (int i = 0; i < 4; ++i) {
      const unsigned __int128 s = static_cast<unsigned __int128>(a.w[i]) + b.w[i] + carry;
      r.w[i] = static_cast<uint64_t>(s);
      carry = s >> 64;
    }
    return r;
  }
  friend Int256 operator-(const Int256& a) {
    Int256 r;
    for (int i = 0; i < 4; ++i) r.w[i] = ~a.w[i];
    return r + From(1);
  }
  friend Int256 operator-(const Int256& a, const Int256& b) { return a + (-b); }
  friend Int256 operator*(const Int256& a, const Int256& b) {
    Int256 r;
    for (int i = 0; i < 4; ++i) {
      unsigned __int128 carry = 0;
      for (int j = 0; i + j < 4; ++j) {
        const unsigned __int128 t =
            static_cast<unsigned __int128>(a.w[i]) * b.w[j] + r.w[i + j] + carry;
        r.w[i + j] = static_cast<uint64_t>(t);
        carry = t >> 64;
      }
    }
    return r;
  }
  int Sign() const {
    if (w[3] >> 63) return -1;
    return (w[0] | w[1] | w[2] | w[3]) != 0 ? 1 : 0;
  }
};

// The power of two that makes every coordinate of `points` an integer.
int ScaleExponent(const std::vector<Point2>& points) {
  int exponent = 0;
  for (const Point2& p : points) {
    for (double x : p) {
      if (x == 0) continue;
      int e;
      const double m = std::frexp(x, &e);  // x = m 2^e, 0.5 <= |m| < 1
      auto significand = static_cast<int64_t>(std::ldexp(m, 53));
      int low = e - 53;
      while ((significand & 1) == 0) {
        significand >>= 1;
        ++low;
      }
      exponent = std::max(exponent, -low);
    }
  }
  return exponent;
}

// Coordinate differences p - origin as exact integers (scaled by 2^exponent).
std::array<Int256, 2> ScaledDifference(const Point2& p, const Point2& origin, int exponent) {
  std::array<Int256, 2> d;
  for (int k = 0; k < 2; ++k) {
    const double a = std::ldexp(p[k], exponent), b = std::ldexp(origin[k], exponent);
    EXPECT_LT(std::abs(a), 0x1p62);
    EXPECT_LT(std::abs(b), 0x1p62);
    EXPECT_EQ(a, std::trunc(a));
    d[k] = Int256::From(static_cast<__int128>(static_cast<int64_t>(a)) -
                        static_cast<__int128>(static_cast<int64_t>(b)));
  }
  return d;
}

int ExactOrient(const Point2& a, const Point2& b, const Point2& c) {
  const int e = ScaleExponent({a, b, c});
  const auto ac = ScaledDifference(a, c, e), bc = ScaledDifference(b, c, e);
  return (ac[0] * bc[1] - ac[1] * bc[0]).Sign();
}

int ExactInCircle(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const int e = ScaleExponent({a, b, c, d});
  const auto ad = ScaledDifference(a, d, e), bd = ScaledDifference(b, d, e),
             cd = ScaledDifference(c, d, e);
  const Int256 alift = ad[0] * ad[0] + ad[1] * ad[1];
  const Int256 blift = bd[0] * bd[0] + bd[1] * bd[1];
  const Int256 clift = cd[0] * cd[0] + cd[1] * cd[1];
  return (alift * (bd[0] * cd[1] - cd[0] * bd[1]) + blift * (cd[0] * ad[1] - ad[0] * cd[1]) +
          clift * (ad[0] * bd[1] - bd[0] * ad[1]))
      .Sign();
}

int SignOf(double x) { return (x > 0) - (x < 0); }

// The same determinants in plain doubles, as a naive implementation would write them.
double NaiveOrient(const Point2& a, const Point2& b, const Point2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}
double NaiveInCircle(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const double adx = a[0] - d[0], ady = a[1] - d[1], bdx = b[0] - d[0], bdy = b[1] - d[1],
               cdx = c[0] - d[0], cdy = c[1] - d[1];
  return (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy) +
         (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy) +
         (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady);
}

// Kettner et al.'s "classroom example": p on a fine grid of ulps around (base, base), against the
// line through (24 base, 24 base) and (48 base, 48 base). Plain doubles give a chaotic pattern of
// signs when the line's length times the rounding error of a double is about an ulp of base.
void CheckNearLine(double base) {
  const double ulp = std::nextafter(base, 2 * base + 1) - base;
  const Point2 q{24 * base, 24 * base}, r{48 * base, 48 * base};
  int naive_wrong = 0, zero = 0;
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 64; ++j) {
      const Point2 p{base + i * ulp, base + j * ulp};
      const int exact = ExactOrient(p, q, r);
      ASSERT_EQ(SignOf(Orient2d(p, q, r)), exact) << "base " << base << " i " << i << " j " << j;
      ASSERT_EQ(SignOf(Orient2d(q, r, p)), exact);
      ASSERT_EQ(SignOf(Orient2d(q, p, r)), -exact);
      naive_wrong += SignOf(NaiveOrient(p, q, r)) != exact;
      zero += exact == 0;
    }
  }
  EXPECT_GT(naive_wrong, 0) << "the input is too easy to test anything";
  EXPECT_EQ(zero, 64);  // the diagonal i == j
}

TEST(RobustPredicatesTest, Orient2dOnPointsUlpsOffALine) { CheckNearLine(0.5); }

TEST(RobustPredicatesTest, Orient2dOnPointsUlpsOffALineFarFromTheOrigin) {
  CheckNearLine(1e6 + 0.5);
}

TEST(RobustPredicatesTest, Orient2dRandomNearlyCollinear) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0, 1);
  int naive_wrong[2] = {0, 0};
  for (int trial = 0; trial < 20000; ++trial) {
    // Coordinates in [1, 2), or 1e6 + [0, 2^20): one exponent range each, so that the exact
    // reference's integers stay in range.
    const bool far = trial % 2 == 1;
    const double offset = far ? 1e6 : 1, spread = far ? 0x1p20 : 1;
    auto coordinate = [&] { return offset + spread * unit(random); };
    const Point2 a{coordinate(), coordinate()}, b{coordinate(), coordinate()};
    const double t = unit(random);
    // A point on the line a b, rounded, then nudged by up to two ulps in each coordinate.
    Point2 c{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
    for (double& x : c) {
      const int nudge = static_cast<int>(random() % 5) - 2;
      for (int k = 0; k < std::abs(nudge); ++k) x = std::nextafter(x, nudge > 0 ? 1e300 : -1e300);
    }
    const int exact = ExactOrient(a, b, c);
    ASSERT_EQ(SignOf(Orient2d(a, b, c)), exact) << "trial " << trial;
    naive_wrong[far] += SignOf(NaiveOrient(a, b, c)) != exact;
  }
  EXPECT_GT(naive_wrong[0], 0);
  EXPECT_GT(naive_wrong[1], 0);
}

// The 20 integer points at distance 25 from a centre (7-24-25 and 15-20-25 triangles).
std::vector<Point2> CircleOf25(double cx, double cy) {
  std::vector<Point2> points;
  for (const auto& [x, y] : {std::pair{25, 0}, std::pair{24, 7}, std::pair{20, 15},
                             std::pair{15, 20}, std::pair{7, 24}}) {
    for (const auto& [sx, sy] :
         {std::pair{1, 1}, std::pair{-1, 1}, std::pair{-1, -1}, std::pair{1, -1}}) {
      points.push_back({cx + sx * x, cy + sy * y});
      points.push_back({cx - sy * y, cy + sx * x});  // rotated a quarter turn
    }
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}

TEST(RobustPredicatesTest, InCircleIsZeroOnCocircularPoints) {
  for (const double offset : {0.0, 1e6 + 0.25, -1e8 - 0.5}) {
    // Unit squares of a grid: every raster cell's four centres.
    for (int i = 0; i < 4; ++i) {
      const Point2 a{offset + i, offset}, b{offset + i + 1, offset}, c{offset + i + 1, offset + 1},
          d{offset + i, offset + 1};
      EXPECT_EQ(InCircle(a, b, c, d), 0.0);
      EXPECT_EQ(ExactInCircle(a, b, c, d), 0);
    }
    const std::vector<Point2> circle = CircleOf25(offset, offset + 3);
    ASSERT_EQ(circle.size(), 20u);
    int naive_nonzero = 0;
    for (size_t i = 0; i + 3 < circle.size(); ++i) {
      const Point2 &a = circle[i], &b = circle[i + 1], &c = circle[i + 2], &d = circle[i + 3];
      EXPECT_EQ(InCircle(a, b, c, d), 0.0) << "offset " << offset << " i " << i;
      EXPECT_EQ(ExactInCircle(a, b, c, d), 0);
      // The same points evaluated without translating to d first (as a naive lifted
      // determinant would) lose the zero at large offsets.
      const auto lift = [](const Point2& p) { return p[0] * p[0] + p[1] * p[1]; };
      const double naive =
          (a[0] - d[0]) *
              ((b[1] - d[1]) * (lift(c) - lift(d)) - (c[1] - d[1]) * (lift(b) - lift(d))) -
          (a[1] - d[1]) *
              ((b[0] - d[0]) * (lift(c) - lift(d)) - (c[0] - d[0]) * (lift(b) - lift(d))) +
          (lift(a) - lift(d)) * ((b[0] - d[0]) * (c[1] - d[1]) - (c[0] - d[0]) * (b[1] - d[1]));
      naive_nonzero += naive != 0;
    }
    if (std::abs(offset) > 1e7) {  // squares beyond 2^53: the naive lift rounds
      EXPECT_GT(naive_nonzero, 0);
    }
  }
}

TEST(RobustPredicatesTest, InCircleOnPointsUlpsOffACircle) {
  int naive_wrong = 0, checked = 0;
  for (const double offset : {0.0, 1e6 + 0.25, -3e7 - 0.5}) {
    const std::vector<Point2> circle = CircleOf25(offset + 0.125, offset + 3);
    for (size_t i = 0; i + 3 < circle.size(); ++i) {
      // a, b, c counter-clockwise on the circle (sorted points are not in angular order).
      Point2 a = circle[i], b = circle[i + 1], c = circle[i + 2];
      if (Orient2d(a, b, c) < 0) std::swap(a, b);
      for (int dx = -2; dx <= 2; ++dx) {
        for (int dy = -2; dy <= 2; ++dy) {
          Point2 d = circle[i + 3];
          for (int k = 0; k < std::abs(dx); ++k) d[0] = std::nextafter(d[0], dx * 1e300);
          for (int k = 0; k < std::abs(dy); ++k) d[1] = std::nextafter(d[1], dy * 1e300);
          const int exact = ExactInCircle(a, b, c, d);
          ASSERT_EQ(SignOf(InCircle(a, b, c, d)), exact)
              << "offset " << offset << " i " << i << " dx " << dx << " dy " << dy;
          ASSERT_EQ(SignOf(InCircle(b, c, a, d)), exact);
          ASSERT_EQ(SignOf(InCircle(b, a, c, d)), -exact);
          naive_wrong += SignOf(NaiveInCircle(a, b, c, d)) != exact;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(naive_wrong, 0) << "of " << checked;
}

TEST(RobustPredicatesTest, InCircleRandomNearlyCocircular) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  int naive_wrong = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double offset = trial % 2 == 0 ? 0 : 1e6;
    const double cx = offset + unit(random), cy = offset + unit(random), radius = 1 + unit(random);
    // Rounded to multiples of 2^-40 near the origin, so that the exact reference stays in range.
    const double grid = offset == 0 ? 0x1p-40 : 0;
    auto on_circle = [&] {
      const double angle = 3.14159 * unit(random);
      Point2 p{cx + radius * std::cos(angle), cy + radius * std::sin(angle)};
      if (grid != 0) {
        for (double& x : p) x = std::round(x / grid) * grid;
      }
      return p;
    };
    Point2 a = on_circle(), b = on_circle(), c = on_circle(), d = on_circle();
    if (Orient2d(a, b, c) < 0) std::swap(a, b);
    const int exact = ExactInCircle(a, b, c, d);
    ASSERT_EQ(SignOf(InCircle(a, b, c, d)), exact) << "trial " << trial;
    naive_wrong += SignOf(NaiveInCircle(a, b, c, d)) != exact;
  }
  EXPECT_GT(naive_wrong, 0);
}

TEST(RobustPredicatesTest, EasyCasesAndMagnitudes) {
  EXPECT_EQ(Orient2d({0, 0}, {1, 0}, {0, 1}), 1.0);
  EXPECT_EQ(Orient2d({0, 0}, {0, 1}, {1, 0}), -1.0);
  EXPECT_EQ(Orient2d({0, 0}, {1, 1}, {3, 3}), 0.0);
  EXPECT_GT(InCircle({0, 0}, {2, 0}, {0, 2}, {1, 1}), 0);
  EXPECT_LT(InCircle({0, 0}, {2, 0}, {0, 2}, {3, 3}), 0);
  EXPECT_EQ(InCircle({0, 0}, {2, 0}, {0, 2}, {2, 2}), 0.0);
}

}  // namespace
}  // namespace geodex::terrain
