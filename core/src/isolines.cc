// Approximate isolines (paper section 6.1): one straight segment per face and level, where the
// linearly interpolated vertex distance crosses the level; segments are stitched through the edge
// points they share.

#include "geodex/isolines.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "absl/strings/str_format.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"

namespace geodex {
namespace {

// A face's segment for one level: from the point on half-edge `a` to the point on half-edge `b`.
struct Segment {
  uint32_t a, b;
};

// The same undirected edge for both half-edges of an interior edge.
uint32_t EdgeKey(const TriangleMesh& mesh, uint32_t h) {
  const uint32_t twin = mesh.Twin(h);
  return twin != kNoIndex && twin < h ? twin : h;
}

class LevelStitcher {
 public:
  LevelStitcher(const TriangleMesh& mesh, const double* d)
      : mesh_(mesh), d_(d), node_of_(3 * static_cast<size_t>(mesh.face_count()), kNoIndex) {}

  // Appends the polylines of `level` made of `segments`.
  void Stitch(double level, const std::vector<Segment>& segments,
              std::vector<IsolinePolyline>* out) {
    level_ = level;
    keys_.clear();
    adjacency_.clear();
    ends_.resize(segments.size());
    for (uint32_t s = 0; s < segments.size(); ++s) {
      const uint32_t na = Node(segments[s].a), nb = Node(segments[s].b);
      Attach(na, s);
      Attach(nb, s);
      ends_[s] = {na, nb};
    }
    used_.assign(segments.size(), false);
    // Open polylines start at a node with one segment; what is left afterwards are loops.
    for (uint32_t n = 0; n < keys_.size(); ++n) {
      if (adjacency_[2 * n + 1] == kNoIndex && !used_[adjacency_[2 * n]]) Walk(n, false, out);
    }
    for (uint32_t s = 0; s < segments.size(); ++s) {
      if (!used_[s]) Walk(ends_[s][0], true, out);
    }
    for (uint32_t key : keys_) node_of_[key] = kNoIndex;
  }

 private:
  uint32_t Node(uint32_t h) {
    const uint32_t key = EdgeKey(mesh_, h);
    if (node_of_[key] == kNoIndex) {
      node_of_[key] = static_cast<uint32_t>(keys_.size());
      keys_.push_back(key);
      adjacency_.push_back(kNoIndex);
      adjacency_.push_back(kNoIndex);
    }
    return node_of_[key];
  }

  void Attach(uint32_t node, uint32_t segment) {
    // Each edge borders at most two faces, and a face has one segment per level.
    adjacency_[2 * node + (adjacency_[2 * node] == kNoIndex ? 0 : 1)] = segment;
  }

  void Walk(uint32_t start, bool closed, std::vector<IsolinePolyline>* out) {
    std::vector<uint32_t> nodes{start};
    uint32_t node = start;
    uint32_t seg = adjacency_[2 * node];
    if (used_[seg]) seg = adjacency_[2 * node + 1];
    const bool forward = ends_[seg][0] == start;  // the walk follows the first segment's direction
    while (seg != kNoIndex && !used_[seg]) {
      used_[seg] = true;
      node = ends_[seg][0] == node ? ends_[seg][1] : ends_[seg][0];
      const uint32_t s0 = adjacency_[2 * node], s1 = adjacency_[2 * node + 1];
      seg = s0 == seg ? s1 : s0;
      if (node == start) break;  // the loop closed
      nodes.push_back(node);
    }
    if (!forward) std::reverse(nodes.begin(), nodes.end());
    IsolinePolyline line;
    line.level = level_;
    line.closed = closed;
    uint32_t last_vertex_hit = kNoIndex;
    for (uint32_t n : nodes) {
      uint32_t hit = kNoIndex;
      PathPoint p = MakePoint(keys_[n], &hit);
      if (hit != kNoIndex && hit == last_vertex_hit) continue;  // the same vertex again
      last_vertex_hit = hit;
      line.points.push_back(p);
    }
    if (closed && line.points.size() > 1 && last_vertex_hit != kNoIndex) {
      uint32_t first_hit = kNoIndex;
      MakePoint(keys_[nodes.front()], &first_hit);
      if (first_hit == last_vertex_hit) line.points.pop_back();
    }
    if (line.points.size() < 3) line.closed = false;  // collapsed onto vertices at the level
    if (line.points.size() >= 2) out->push_back(std::move(line));
  }

  // The edge point of the level on the edge of half-edge h; *vertex_hit is the internal vertex
  // when the point is (snapped to) that vertex.
  PathPoint MakePoint(uint32_t h, uint32_t* vertex_hit) const {
    uint32_t from = mesh_.From(h), to = mesh_.To(h);
    if (!(d_[from] < level_)) std::swap(from, to);
    double t = (level_ - d_[from]) / (d_[to] - d_[from]);
    *vertex_hit = kNoIndex;
    // The edge-parameter rule of surface points (kSurfaceSnap): a level equal to a vertex's
    // distance up to round-off gives one point there, not a cluster.
    if (t >= 1 - kSurfaceSnap) {
      t = 1;
      *vertex_hit = to;
    } else if (t <= kSurfaceSnap) {
      t = 0;
      *vertex_hit = from;
    }
    const double* pa = mesh_.positions() + 3 * from;
    const double* pb = mesh_.positions() + 3 * to;
    PathPoint p;
    for (int k = 0; k < 3; ++k) {
      const double x = t == 1 ? pb[k] : t == 0 ? pa[k] : pa[k] + t * (pb[k] - pa[k]);
      p.position[k] = x + mesh_.Center()[k];
    }
    p.where = SurfacePoint::OnEdge(mesh_.FileVertex(from), mesh_.FileVertex(to), t);
    return p;
  }

  const TriangleMesh& mesh_;
  const double* d_;
  double level_ = 0;
  std::vector<uint32_t> node_of_;    // per half-edge key: node id for the current level
  std::vector<uint32_t> keys_;       // per node: its edge key
  std::vector<uint32_t> adjacency_;  // per node: two segment slots
  std::vector<std::array<uint32_t, 2>> ends_;
  std::vector<bool> used_;
};

absl::StatusOr<std::vector<double>> ChooseLevels(const DistanceField& field,
                                                 const IsolineOptions& options) {
  if (absl::Status s = ValidateIsolineOptions(options); !s.ok()) return s;
  std::vector<double> levels = options.levels;
  if (levels.empty()) {
    double max_d = 0;
    for (double d : field.internal_distance) {
      if (std::isfinite(d)) max_d = std::max(max_d, d);
    }
    for (int j = 1; j < options.count; ++j) levels.push_back(max_d * j / options.count);
  }
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  return levels;
}

}  // namespace

absl::Status ValidateIsolineOptions(const IsolineOptions& options, uint64_t max_levels) {
  if (options.levels.size() > max_levels) {
    return OptionError(
        "levels",
        absl::StrFormat("%d levels, over the limit of %d", options.levels.size(), max_levels),
        absl::StatusCode::kResourceExhausted);
  }
  for (size_t i = 0; i < options.levels.size(); ++i) {
    if (!std::isfinite(options.levels[i])) {
      return OptionError(absl::StrFormat("levels[%d]", i),
                         absl::StrFormat("must be finite, got %g", options.levels[i]));
    }
  }
  if (!options.levels.empty()) return absl::OkStatus();
  if (options.count < 2) {
    return OptionError("count",
                       absl::StrFormat("give levels, or a count >= 2 (got %d)", options.count));
  }
  if (static_cast<uint64_t>(options.count) - 1 > max_levels) {
    return OptionError("count",
                       absl::StrFormat("%d gives %d levels, over the limit of %d", options.count,
                                       options.count - 1, max_levels),
                       absl::StatusCode::kResourceExhausted);
  }
  return absl::OkStatus();
}

absl::StatusOr<Isolines> ExtractIsolines(const TriangleMesh& mesh, const DistanceField& field,
                                         const IsolineOptions& options) {
  if (field.internal_distance.size() != mesh.vertex_count()) {
    return absl::InvalidArgumentError("the distance field was not computed on this mesh");
  }
  absl::StatusOr<std::vector<double>> levels = ChooseLevels(field, options);
  if (!levels.ok()) return levels.status();
  Isolines result;
  result.levels = *std::move(levels);
  const std::vector<double>& lv = result.levels;
  const double* d = field.internal_distance.data();

  // One pass over the faces: face f crosses level L iff min d < L <= max d (d >= L is "above"),
  // i.e. for a contiguous range of the sorted levels. The lone vertex x (alone on its side) is
  // between the two crossed edges x->x+1 and x+2->x; the segment runs so that the lower side is
  // on the left: x+1-edge to x+2-edge when x is below, the reverse when x is above.
  std::vector<std::vector<Segment>> segments(lv.size());
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    const double df[3] = {d[mesh.FaceVertex(f, 0)], d[mesh.FaceVertex(f, 1)],
                          d[mesh.FaceVertex(f, 2)]};
    if (!std::isfinite(df[0]) || !std::isfinite(df[1]) || !std::isfinite(df[2])) continue;
    const double lo = std::min({df[0], df[1], df[2]}), hi = std::max({df[0], df[1], df[2]});
    auto first = std::upper_bound(lv.begin(), lv.end(), lo);
    auto last = std::upper_bound(lv.begin(), lv.end(), hi);
    for (auto it = first; it != last; ++it) {
      const double level = *it;
      const bool above[3] = {df[0] >= level, df[1] >= level, df[2] >= level};
      int x = 0;
      while (above[x] == above[(x + 1) % 3] || above[x] == above[(x + 2) % 3]) ++x;
      const uint32_t h_next = 3 * f + x, h_prev = 3 * f + (x + 2) % 3;
      segments[it - lv.begin()].push_back(above[x] ? Segment{h_prev, h_next}
                                                   : Segment{h_next, h_prev});
    }
  }
  LevelStitcher stitcher(mesh, d);
  for (size_t i = 0; i < lv.size(); ++i) stitcher.Stitch(lv[i], segments[i], &result.polylines);
  return result;
}

}  // namespace geodex
