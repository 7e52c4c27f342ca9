#include "robust_predicates.h"

#include <cmath>

// Every operation below relies on each double operation being rounded on its own (IEEE 754
// round-to-nearest-even, no fused multiply-add contracted by the compiler, no extended-precision
// registers): terrain/CMakeLists.txt compiles this file with -ffp-contract=off. x86-64 and ARM64
// do the rest.

namespace geodex::terrain {
namespace {

// Half an ulp of 1: the relative error of one rounded operation.
constexpr double kEpsilon = 0x1p-53;
// Bounds on the rounding error of the plain-double determinants below, relative to the sum of
// the magnitudes of their terms (Shewchuk's ccwerrboundA and iccerrboundA: they hold for exactly
// the evaluation order used in Orient2d and InCircle, so do not reorder those expressions).
constexpr double kOrientBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
constexpr double kInCircleBound = (10.0 + 96.0 * kEpsilon) * kEpsilon;
// 2^27 + 1: splits a double's 53-bit significand into two halves of at most 26 bits each.
constexpr double kSplitter = 0x1p27 + 1.0;

// --- Error-free transformations: a op b = x + y exactly, x the rounded result. ---

void TwoSum(double a, double b, double& x, double& y) {
  x = a + b;
  const double b_virtual = x - a;
  const double a_virtual = x - b_virtual;
  y = (a - a_virtual) + (b - b_virtual);
}

// As TwoSum, when |a| >= |b| (or a is zero): three operations instead of six.
void FastTwoSum(double a, double b, double& x, double& y) {
  x = a + b;
  y = b - (x - a);
}

void TwoDiff(double a, double b, double& x, double& y) {
  x = a - b;
  const double b_virtual = a - x;
  const double a_virtual = x + b_virtual;
  y = (a - a_virtual) + (b_virtual - b);
}

// Dekker's split: a = high + low, each fitting in 26 bits, so products of halves are exact.
void Split(double a, double& high, double& low) {
  const double c = kSplitter * a;
  const double big = c - a;
  high = c - big;
  low = a - high;
}

void TwoProduct(double a, double b, double& x, double& y) {
  x = a * b;
  double a_high, a_low, b_high, b_low;
  Split(a, a_high, a_low);
  Split(b, b_high, b_low);
  const double error1 = x - a_high * b_high;
  const double error2 = error1 - a_low * b_high;
  const double error3 = error2 - a_high * b_low;
  y = a_low * b_low - error3;
}

// --- Expansions: a real number as a sum of doubles, ordered by increasing magnitude, no two
// overlapping (strongly non-overlapping, in Shewchuk's terms), zeros removed. Its sign is the
// sign of its last (largest) component. `N` is the most components it can have. ---

template <int N>
struct Expansion {
  int size = 0;
  double c[N];  // c[0 .. size), smallest first

  // The largest component: the sign of the value, and its magnitude within a factor of 2 (the
  // others add up to less than its lowest bit). Summing the components could round to zero.
  double Leading() const { return size == 0 ? 0.0 : c[size - 1]; }
};

// a - b exactly.
Expansion<2> Difference(double a, double b) {
  Expansion<2> e;
  double x, y;
  TwoDiff(a, b, x, y);
  if (y != 0) e.c[e.size++] = y;
  if (x != 0) e.c[e.size++] = x;
  return e;
}

// The same difference when it is known to be exact (its tail zero).
Expansion<1> ExactDifference(double a, double b) {
  Expansion<1> e;
  const double x = a - b;
  if (x != 0) e.c[e.size++] = x;
  return e;
}

// h = e + f (h has room for elen + flen components). Merges the two by magnitude, then carries
// the running sum up through them, keeping each non-zero rounding error as a component (the
// linear-time "fast expansion sum" with zero elimination).
int SumInto(const double* e, int elen, const double* f, int flen, double* h) {
  if (elen == 0 || flen == 0) {
    const double* from = elen == 0 ? f : e;
    const int n = elen == 0 ? flen : elen;
    for (int i = 0; i < n; ++i) h[i] = from[i];
    return n;
  }
  int i = 0, j = 0, k = 0;
  auto next_smallest = [&]() {
    if (j == flen || (i < elen && std::abs(e[i]) < std::abs(f[j]))) return e[i++];
    return f[j++];
  };
  double q = next_smallest();
  double g = next_smallest();
  double tail;
  FastTwoSum(g, q, q, tail);  // |g| >= |q|: merged in order of magnitude
  if (tail != 0) h[k++] = tail;
  while (i < elen || j < flen) {
    g = next_smallest();
    TwoSum(q, g, q, tail);
    if (tail != 0) h[k++] = tail;
  }
  if (q != 0) h[k++] = q;
  return k;
}

// h = e * b (h has room for 2 elen components).
int ScaleInto(const double* e, int elen, double b, double* h) {
  if (elen == 0 || b == 0) return 0;
  int k = 0;
  double q, tail;
  TwoProduct(e[0], b, q, tail);
  if (tail != 0) h[k++] = tail;
  for (int i = 1; i < elen; ++i) {
    double product_high, product_low, sum;
    TwoProduct(e[i], b, product_high, product_low);
    TwoSum(q, product_low, sum, tail);
    if (tail != 0) h[k++] = tail;
    FastTwoSum(product_high, sum, q, tail);
    if (tail != 0) h[k++] = tail;
  }
  if (q != 0) h[k++] = q;
  return k;
}

template <int N, int M>
Expansion<N + M> operator+(const Expansion<N>& e, const Expansion<M>& f) {
  Expansion<N + M> h;
  h.size = SumInto(e.c, e.size, f.c, f.size, h.c);
  return h;
}

template <int N>
Expansion<N> operator-(const Expansion<N>& e) {
  Expansion<N> h = e;
  for (int i = 0; i < h.size; ++i) h.c[i] = -h.c[i];
  return h;
}

template <int N, int M>
Expansion<N + M> operator-(const Expansion<N>& e, const Expansion<M>& f) {
  return e + (-f);
}

// e * f: e scaled by each component of f, the partial products summed.
template <int N, int M>
Expansion<2 * N * M> operator*(const Expansion<N>& e, const Expansion<M>& f) {
  Expansion<2 * N * M> sum;
  double partial[2 * N];
  double next[2 * N * M];
  for (int j = 0; j < f.size; ++j) {
    const int partial_size = ScaleInto(e.c, e.size, f.c[j], partial);
    const int size = SumInto(sum.c, sum.size, partial, partial_size, next);
    for (int i = 0; i < size; ++i) sum.c[i] = next[i];
    sum.size = size;
  }
  return sum;
}

// The determinants evaluated exactly from exact coordinate differences (expansions of at most K
// components: 1 when every difference was exact in doubles, as on a raster's grid, else 2).
template <int K>
double Orient2dExact(const Expansion<K>& acx, const Expansion<K>& acy, const Expansion<K>& bcx,
                     const Expansion<K>& bcy) {
  return (acx * bcy - acy * bcx).Leading();
}

template <int K>
double InCircleExact(const Expansion<K>& adx, const Expansion<K>& ady, const Expansion<K>& bdx,
                     const Expansion<K>& bdy, const Expansion<K>& cdx, const Expansion<K>& cdy) {
  const auto alift = adx * adx + ady * ady;
  const auto blift = bdx * bdx + bdy * bdy;
  const auto clift = cdx * cdx + cdy * cdy;
  const auto bc = bdx * cdy - cdx * bdy;
  const auto ca = cdx * ady - adx * cdy;
  const auto ab = adx * bdy - bdx * ady;
  return (alift * bc + blift * ca + clift * ab).Leading();
}

bool Exact(double a, double b) {
  double x, y;
  TwoDiff(a, b, x, y);
  return y == 0;
}

}  // namespace

double Orient2d(const std::array<double, 2>& a, const std::array<double, 2>& b,
                const std::array<double, 2>& c) {
  const double left = (a[0] - c[0]) * (b[1] - c[1]);
  const double right = (a[1] - c[1]) * (b[0] - c[0]);
  const double det = left - right;
  // When the two products differ in sign (or one is zero) their difference cannot cancel: the
  // rounded result has the right sign.
  double magnitude;
  if (left > 0) {
    if (right <= 0) return det;
    magnitude = left + right;
  } else if (left < 0) {
    if (right >= 0) return det;
    magnitude = -left - right;
  } else {
    return det;
  }
  const double bound = kOrientBound * magnitude;
  if (det >= bound || -det >= bound) return det;

  if (Exact(a[0], c[0]) && Exact(a[1], c[1]) && Exact(b[0], c[0]) && Exact(b[1], c[1])) {
    return Orient2dExact(ExactDifference(a[0], c[0]), ExactDifference(a[1], c[1]),
                         ExactDifference(b[0], c[0]), ExactDifference(b[1], c[1]));
  }
  return Orient2dExact(Difference(a[0], c[0]), Difference(a[1], c[1]), Difference(b[0], c[0]),
                       Difference(b[1], c[1]));
}

double InCircle(const std::array<double, 2>& a, const std::array<double, 2>& b,
                const std::array<double, 2>& c, const std::array<double, 2>& d) {
  const double adx = a[0] - d[0], ady = a[1] - d[1];
  const double bdx = b[0] - d[0], bdy = b[1] - d[1];
  const double cdx = c[0] - d[0], cdy = c[1] - d[1];

  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double alift = adx * adx + ady * ady;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double blift = bdx * bdx + bdy * bdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double clift = cdx * cdx + cdy * cdy;

  const double det =
      alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * alift +
                           (std::abs(cdxady) + std::abs(adxcdy)) * blift +
                           (std::abs(adxbdy) + std::abs(bdxady)) * clift;
  const double bound = kInCircleBound * permanent;
  if (det > bound || -det > bound) return det;

  if (Exact(a[0], d[0]) && Exact(a[1], d[1]) && Exact(b[0], d[0]) && Exact(b[1], d[1]) &&
      Exact(c[0], d[0]) && Exact(c[1], d[1])) {
    return InCircleExact(ExactDifference(a[0], d[0]), ExactDifference(a[1], d[1]),
                         ExactDifference(b[0], d[0]), ExactDifference(b[1], d[1]),
                         ExactDifference(c[0], d[0]), ExactDifference(c[1], d[1]));
  }
  return InCircleExact(Difference(a[0], d[0]), Difference(a[1], d[1]), Difference(b[0], d[0]),
                       Difference(b[1], d[1]), Difference(c[0], d[0]), Difference(c[1], d[1]));
}

}  // namespace geodex::terrain
