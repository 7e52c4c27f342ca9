#pragma once

// The engine's tolerances and small geometric helpers, shared by its files. Numerical policy
// (docs/numerics.md): every tolerance is relative to the geometry at hand.

#include <cmath>
#include <cstdint>

namespace geodex::ich {

// Filter ties keep the window: it is killed only when worse by more than this fraction of the
// distances compared (so a vertex distance set by the window's own parent never kills it).
constexpr double kFilterRelTol = 1e-12;
// The opposite vertex counts as seen by a window when its ray crosses within this fraction of the
// edge length of the interval (generous: a spurious second child is harmless, a missed one is not).
constexpr double kCoverRelTol = 1e-10;
// Windows narrower than this fraction of their edge carry no path that a neighbouring window or
// an endpoint vertex does not also carry.
constexpr double kTinyWindowRel = 1e-13;
// An image closer than this (relative to the edge) to the edge's line sends rays along the edge,
// never into the face.
constexpr double kGrazingRel = 1e-13;
// Lemma 1 treats distances or crossing points this close as ties and then keeps both children.
constexpr double kSplitTieRel = 1e-12;
// Windows whose keys differ by less than this fraction of the mean edge length are processed in
// any (deterministic) order: see WindowQueue.
constexpr double kQueueResolutionEdges = 0.5;
// On regions with boundary points (region_links.h) the order must be far finer: the points lie
// closer than an edge (geometrically closer towards each vertex), a point's cost passes to the
// next along the chain within a slot, and every drop after a point was processed makes it emit
// again. On the friction case half an edge processed each point 33 times; a thousandth,
// about once, for a quarter of the time and the same answers (docs/performance.md).
constexpr double kRegionQueueResolutionEdges = 1e-3;
// Cancellation is polled every this many dequeued windows.
constexpr uint32_t kCancelPollInterval = 1024;

constexpr double kPi = 3.14159265358979323846;

inline double Hypot(double x, double y) { return std::sqrt(x * x + y * y); }

// Where the ray from image (ix, iy) through edge point (b, 0) meets the segment from p to p + w,
// as a parameter in [0, 1] (clamped: the caller knows the ray hits that segment).
inline double RayHitParam(double ix, double iy, double b, double px, double py, double wx,
                          double wy) {
  const double dx = b - ix, dy = -iy;
  const double denom = wx * dy - wy * dx;
  const double numer = (ix - px) * dy - (iy - py) * dx;
  // I + s D = P + t W, crossed with D: (I - P) x D = t (W x D), with a x b = a.x b.y - a.y b.x.
  double t = denom != 0 ? numer / denom : 0.0;
  if (!(t > 0)) t = 0;  // also catches NaN
  if (t > 1) t = 1;
  return t;
}

}  // namespace geodex::ich
