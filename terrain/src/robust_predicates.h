#pragma once

// Orientation and in-circle tests in the plane whose signs are exact for any finite double
// coordinates (barring overflow and underflow: magnitudes between about 1e-140 and 1e140), in the
// manner of Shewchuk's adaptive-precision predicates ("Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates", 1997): the determinant is first evaluated in
// plain doubles together with a bound on its rounding error; only when the bound does not settle
// the sign is it recomputed exactly, as a floating-point expansion (a sum of non-overlapping
// doubles). The fast path decides almost every call; the exact one runs on near-degenerate input,
// which a raster's grid points (collinear rows, cocircular squares) produce all the time.
//
// Why exact: a Delaunay triangulation built on signs that rounding can flip may walk in circles,
// flip an edge back and forth, or create inverted triangles. With exact signs every decision is
// consistent with one real configuration of the points.

#include <array>

namespace geodex::terrain {

// Positive when a, b, c turn counter-clockwise (c lies left of the line a -> b, with y up),
// negative when clockwise, zero when collinear. The magnitude approximates twice the triangle's
// signed area; only the sign is exact.
double Orient2d(const std::array<double, 2>& a, const std::array<double, 2>& b,
                const std::array<double, 2>& c);

// For a, b, c counter-clockwise: positive when d lies strictly inside their circumcircle, negative
// outside, zero on it (the sign flips when a, b, c are clockwise). The magnitude approximates the
// lifted determinant; only the sign is exact.
double InCircle(const std::array<double, 2>& a, const std::array<double, 2>& b,
                const std::array<double, 2>& c, const std::array<double, 2>& d);

}  // namespace geodex::terrain
