#include "geodex/locate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace geodex {
namespace {

using Vec3 = std::array<double, 3>;

constexpr uint32_t kMaxLeafSize = 4;
constexpr int kBins = 16;
// Below this depth splits follow the binned SAH; deeper ones fall back to the object median, which
// halves the count, so the tree depth stays below kSahDepth + 32 < kStackSize.
constexpr int kSahDepth = 48;
constexpr int kStackSize = 96;
// Queries farther than this from the mesh centre would overflow squared distances.
constexpr double kMaxQueryOffset = 1e150;

inline Vec3 Sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Half the surface area of a box given as {lo[3], hi[3]}.
inline double HalfArea(const std::array<double, 6>& b) {
  const double dx = b[3] - b[0], dy = b[4] - b[1], dz = b[5] - b[2];
  return dx * dy + dy * dz + dz * dx;
}

// The nearest float <= x / >= x, so a float box still contains what the double box did.
inline float FloatDown(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity())
                                    : f;
}
inline float FloatUp(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

inline void Grow(std::array<double, 6>& into, const std::array<double, 6>& b) {
  for (int a = 0; a < 3; ++a) {
    into[a] = std::min(into[a], b[a]);
    into[a + 3] = std::max(into[a + 3], b[a + 3]);
  }
}

constexpr std::array<double, 6> kEmptyBox = {
    std::numeric_limits<double>::infinity(),  std::numeric_limits<double>::infinity(),
    std::numeric_limits<double>::infinity(),  -std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};

// Closest point of segment (x, y) to p; x and y are corners i and j of the triangle.
TriangleClosestPoint ClosestOnSegment(const Vec3& p, const Vec3& x, const Vec3& y, int i, int j) {
  const Vec3 xy = Sub(y, x), xp = Sub(p, x);
  const double len2 = Dot(xy, xy);
  const double t = len2 > 0 ? std::clamp(Dot(xy, xp) / len2, 0.0, 1.0) : 0;
  TriangleClosestPoint r;
  r.point = t == 1 ? y : Vec3{x[0] + t * xy[0], x[1] + t * xy[1], x[2] + t * xy[2]};
  r.bary = {0, 0, 0};
  r.bary[i] = 1 - t;
  r.bary[j] += t;
  const Vec3 d = Sub(p, r.point);
  r.distance2 = Dot(d, d);
  return r;
}

// For zero-area triangles, which are just their three edges.
TriangleClosestPoint ClosestOnEdges(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  TriangleClosestPoint best = ClosestOnSegment(p, a, b, 0, 1);
  for (const TriangleClosestPoint& r :
       {ClosestOnSegment(p, b, c, 1, 2), ClosestOnSegment(p, c, a, 2, 0)}) {
    if (r.distance2 < best.distance2) best = r;
  }
  return best;
}

// Assumes a triangle of non-zero area (the region tests mistake, e.g., a doubled corner for an
// edge); the locator only sees faces that Build found non-degenerate.
inline TriangleClosestPoint ClosestPoint(const Vec3& p, const Vec3& a, const Vec3& b,
                                         const Vec3& c) {
  auto at = [&](const Vec3& x, double b0, double b1, double b2) {
    const Vec3 d = Sub(p, x);
    return TriangleClosestPoint{x, {b0, b1, b2}, Dot(d, d)};
  };
  const Vec3 ab = Sub(b, a), ac = Sub(c, a), ap = Sub(p, a);
  const double d1 = Dot(ab, ap), d2 = Dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return at(a, 1, 0, 0);
  const Vec3 bp = Sub(p, b);
  const double d3 = Dot(ab, bp), d4 = Dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(b, 0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    // d1 - d3 = |ab|^2: zero only when a and b coincide (then any v in [0, 1] is right).
    const double v = d1 - d3 > 0 ? d1 / (d1 - d3) : 0;
    return at({a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]}, 1 - v, v, 0);
  }
  const Vec3 cp = Sub(p, c);
  const double d5 = Dot(ab, cp), d6 = Dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(c, 0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 - d6 > 0 ? d2 / (d2 - d6) : 0;  // d2 - d6 = |ac|^2
    return at({a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]}, 1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double bc2 = (d4 - d3) + (d5 - d6);  // |bc|^2
    const double w = bc2 > 0 ? (d4 - d3) / bc2 : 0;
    return at({b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])}, 0,
              1 - w, w);
  }
  // Interior. On thin triangles the region tests above can disagree by round-off, so clamp the
  // weights to keep the point on the triangle.
  const double sum = va + vb + vc;                    // |ab x ac|^2
  if (!(sum > 0)) return ClosestOnEdges(p, a, b, c);  // round-off on an almost flat triangle
  const double denom = 1 / sum;
  double v = std::max(0.0, vb * denom), w = std::max(0.0, vc * denom);
  if (v + w > 1) {
    const double s = v + w;
    v /= s;
    w /= s;
  }
  return at(
      {a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w},
      std::max(0.0, 1 - v - w), v, w);
}

}  // namespace

struct SurfaceLocator::BuildScratch {
  std::vector<std::array<double, 3>> centroid;  // of the face's box
  std::vector<std::array<double, 6>> box;       // lo[3], hi[3]
};

TriangleClosestPoint ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                            const Vec3& c) {
  const Vec3 ab = Sub(b, a), ac = Sub(c, a);
  // Exact zero test of the normal (no squaring, which could underflow on tiny triangles).
  if (ab[1] * ac[2] == ab[2] * ac[1] && ab[2] * ac[0] == ab[0] * ac[2] &&
      ab[0] * ac[1] == ab[1] * ac[0]) {
    return ClosestOnEdges(p, a, b, c);
  }
  return ClosestPoint(p, a, b, c);
}

SurfaceLocator::SurfaceLocator(const TriangleMesh& mesh) : mesh_(&mesh) {
  const uint32_t nf = mesh.face_count();
  std::vector<uint32_t> items;
  items.reserve(nf);
  BuildScratch scratch;
  scratch.centroid.resize(nf);
  scratch.box.resize(nf);
  for (uint32_t f = 0; f < nf; ++f) {
    if (mesh.FaceDegenerate(f)) continue;
    items.push_back(f);
    std::array<double, 6> box = kEmptyBox;
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = mesh.Position(mesh.FaceVertex(f, k));
      Grow(box, {p[0], p[1], p[2], p[0], p[1], p[2]});
    }
    scratch.box[f] = box;
    for (int a = 0; a < 3; ++a) scratch.centroid[f][a] = 0.5 * (box[a] + box[a + 3]);
  }
  for (int a = 0; a < 3; ++a) {
    extent_ = std::max({extent_, std::abs(mesh.BoundsMin()[a] - mesh.Center()[a]),
                        std::abs(mesh.BoundsMax()[a] - mesh.Center()[a])});
  }
  if (!items.empty()) {
    // Leaves mostly hold 3-4 faces, so about n/3 inner nodes; reserve generously, trim afterwards.
    nodes_.reserve(items.size() / 2 + 1);
    triangles_.reserve(items.size());
    face_ids_.reserve(items.size());
    std::array<double, 6> bounds;
    root_ = Build(scratch, items, 0, static_cast<uint32_t>(items.size()), 0, &bounds);
    nodes_.shrink_to_fit();
  }
}

SurfaceLocator::Ref SurfaceLocator::Build(const BuildScratch& scratch, std::vector<uint32_t>& items,
                                          uint32_t begin, uint32_t end, int depth,
                                          std::array<double, 6>* bounds_out) {
  const std::vector<std::array<double, 3>>& centroid = scratch.centroid;
  const std::vector<std::array<double, 6>>& box = scratch.box;
  std::array<double, 6> bounds = kEmptyBox, centroid_bounds = kEmptyBox;
  for (uint32_t i = begin; i < end; ++i) {
    const uint32_t f = items[i];
    Grow(bounds, box[f]);
    const Vec3& c = centroid[f];
    Grow(centroid_bounds, {c[0], c[1], c[2], c[0], c[1], c[2]});
  }
  *bounds_out = bounds;
  const uint32_t count = end - begin;
  if (count <= kMaxLeafSize) {
    const Ref leaf{static_cast<uint32_t>(triangles_.size()), count};
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t f = items[i];
      Triangle t;
      for (int k = 0; k < 3; ++k) t.p[k] = mesh_->Position(mesh_->FaceVertex(f, k));
      triangles_.push_back(t);
      face_ids_.push_back(f);
    }
    return leaf;
  }

  // Binned SAH over the centroids on all three axes: cost = half-area x count on each side.
  uint32_t mid = begin;
  if (depth < kSahDepth) {
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_split = 0;
    for (int a = 0; a < 3; ++a) {
      const double lo = centroid_bounds[a], extent = centroid_bounds[a + 3] - lo;
      if (!(extent > 0)) continue;
      const double scale = kBins / extent;
      std::array<uint32_t, kBins> bin_count{};
      std::array<std::array<double, 6>, kBins> bin_box;
      bin_box.fill(kEmptyBox);
      for (uint32_t i = begin; i < end; ++i) {
        const uint32_t f = items[i];
        const int b = std::min(kBins - 1, static_cast<int>((centroid[f][a] - lo) * scale));
        ++bin_count[b];
        Grow(bin_box[b], box[f]);
      }
      // right_cost[s]: bins s..kBins-1.
      std::array<double, kBins> right_cost{};
      std::array<double, 6> sweep = kEmptyBox;
      uint32_t n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        Grow(sweep, bin_box[b]);
        n += bin_count[b];
        right_cost[b] = n ? HalfArea(sweep) * n : 0;
      }
      sweep = kEmptyBox;
      n = 0;
      for (int s = 1; s < kBins; ++s) {  // left = bins 0..s-1
        Grow(sweep, bin_box[s - 1]);
        n += bin_count[s - 1];
        if (n == 0 || n == count) continue;
        const double cost = HalfArea(sweep) * n + right_cost[s];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_split = s;
        }
      }
    }
    if (best_axis >= 0) {
      const double lo = centroid_bounds[best_axis];
      const double scale = kBins / (centroid_bounds[best_axis + 3] - lo);
      auto it = std::partition(items.begin() + begin, items.begin() + end, [&](uint32_t f) {
        return std::min(kBins - 1, static_cast<int>((centroid[f][best_axis] - lo) * scale)) <
               best_split;
      });
      mid = static_cast<uint32_t>(it - items.begin());
    }
  }
  if (mid == begin || mid == end) {
    // Object median on the widest centroid axis (also when all centroids coincide).
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
      if (centroid_bounds[a + 3] - centroid_bounds[a] >
          centroid_bounds[axis + 3] - centroid_bounds[axis]) {
        axis = a;
      }
    }
    mid = begin + count / 2;
    std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                     [&](uint32_t f, uint32_t g) {
                       return centroid[f][axis] < centroid[g][axis] ||
                              (centroid[f][axis] == centroid[g][axis] && f < g);
                     });
  }
  const uint32_t node = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  std::array<std::array<double, 6>, 2> child_bounds;
  const Ref left = Build(scratch, items, begin, mid, depth + 1, &child_bounds[0]);
  const Ref right = Build(scratch, items, mid, end, depth + 1, &child_bounds[1]);
  Node& n = nodes_[node];
  n.child[0] = left;
  n.child[1] = right;
  for (int c = 0; c < 2; ++c) {
    for (int a = 0; a < 3; ++a) {
      n.lo[c][a] = FloatDown(child_bounds[c][a]);
      n.hi[c][a] = FloatUp(child_bounds[c][a + 3]);
    }
  }
  return {node, 0};
}

absl::StatusOr<LocatedPoint> SurfaceLocator::Locate(const Vec3& xyz) const {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(xyz[a])) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "locate: non-finite query coordinate (%g, %g, %g)", xyz[0], xyz[1], xyz[2]));
    }
  }
  if (triangles_.empty()) {
    return absl::FailedPreconditionError("locate: the mesh has no non-degenerate face");
  }
  // Work in recentred coordinates like the mesh, so large georeferenced offsets cancel exactly.
  const Vec3& center = mesh_->Center();
  const Vec3 q = Sub(xyz, center);
  double q_max = 0;
  for (int a = 0; a < 3; ++a) q_max = std::max(q_max, std::abs(q[a]));
  if (!(q_max <= kMaxQueryOffset)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "locate: query (%g, %g, %g) is too far from the mesh", xyz[0], xyz[1], xyz[2]));
  }
  // Computed triangle distances carry round-off of a few ulps of the coordinates involved, so a
  // box is pruned only when it is farther than the best distance plus this allowance. Then every
  // face whose computed distance could tie or beat the best is evaluated, and the result (with its
  // lowest-face-id tie-break) is exactly that of a scan over all faces.
  const double slack = 1e-12 * (extent_ + q_max);

  auto box_distance2 = [&q](const Node& n, int c) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double lo = n.lo[c][a], hi = n.hi[c][a];
      const double gap = std::max({lo - q[a], q[a] - hi, 0.0});  // branch-free
      d2 += gap * gap;
    }
    return d2;
  };

  TriangleClosestPoint best{{}, {}, std::numeric_limits<double>::infinity()};
  uint32_t best_face = kNoIndex;
  double threshold2 = std::numeric_limits<double>::infinity();
  // Depth-first, nearer child first; the farther child waits on a fixed stack with its box
  // distance and is skipped if the best has meanwhile dropped below it.
  std::array<std::pair<Ref, double>, kStackSize> stack;
  int top = 0;
  Ref ref = root_;
  while (true) {
    if (ref.count > 0) {
      for (uint32_t i = ref.index; i < ref.index + ref.count; ++i) {
        const Triangle& t = triangles_[i];
        const TriangleClosestPoint r = ClosestPoint(q, t.p[0], t.p[1], t.p[2]);
        const uint32_t f = face_ids_[i];
        if (r.distance2 < best.distance2 || (r.distance2 == best.distance2 && f < best_face)) {
          best = r;
          best_face = f;
          const double limit = std::sqrt(best.distance2) + slack;
          threshold2 = limit * limit;
        }
      }
    } else {
      const Node& n = nodes_[ref.index];
      double near_d2 = box_distance2(n, 0), far_d2 = box_distance2(n, 1);
      int near = 0;
      if (far_d2 < near_d2) {
        std::swap(near_d2, far_d2);
        near = 1;
      }
      if (far_d2 <= threshold2) stack[top++] = {n.child[1 - near], far_d2};
      if (near_d2 <= threshold2) {
        ref = n.child[near];
        continue;
      }
    }
    while (top > 0 && stack[top - 1].second > threshold2) --top;
    if (top == 0) break;
    ref = stack[--top].first;
  }

  // The nearest point in the file's terms, by the one classifier (a barycentric within
  // kSurfaceSnap of 0 moves the point onto the edge or vertex).
  const uint32_t f = best_face;
  std::array<double, 3> bary = best.bary;
  mesh_->SwapCornerOrder(f, &bary);
  LocatedPoint result;
  result.point = CanonicalFacePoint(f, mesh_->FileCorners(f), bary);
  for (int a = 0; a < 3; ++a) result.position[a] = best.point[a] + center[a];
  result.distance = std::sqrt(best.distance2);
  return result;
}

uint64_t SurfaceLocator::MemoryBytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) +
         triangles_.capacity() * sizeof(Triangle) + face_ids_.capacity() * sizeof(uint32_t);
}

absl::Status CheckSnapDistance(const std::array<double, 3>& query, const LocatedPoint& located,
                               double max_snap) {
  if (!(located.distance > max_snap)) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrFormat("%s is %.6g from the surface, farther than the maximum snap distance %.6g",
                      SurfacePointToString(SurfacePoint::AtPosition(query[0], query[1], query[2])),
                      located.distance, max_snap));
}

}  // namespace geodex
