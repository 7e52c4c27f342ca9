// The approximate Voronoi diagram (paper section 6.2): per face, from the labels and distances at
// its three vertices; boundary segments are stitched through the edge points and junction points
// they share.

#include "geodex/voronoi.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "geodex/travel_cost.h"

namespace geodex {
namespace {

using Vec3 = std::array<double, 3>;

uint32_t EdgeKey(const TriangleMesh& mesh, uint32_t h) {
  const uint32_t twin = mesh.Twin(h);
  return twin != kNoIndex && twin < h ? twin : h;
}

double PolygonArea(const std::vector<Vec3>& p) {
  Vec3 sum{0, 0, 0};
  for (size_t i = 1; i + 1 < p.size(); ++i) {
    const Vec3 a{p[i][0] - p[0][0], p[i][1] - p[0][1], p[i][2] - p[0][2]};
    const Vec3 b{p[i + 1][0] - p[0][0], p[i + 1][1] - p[0][1], p[i + 1][2] - p[0][2]};
    sum[0] += a[1] * b[2] - a[2] * b[1];
    sum[1] += a[2] * b[0] - a[0] * b[2];
    sum[2] += a[0] * b[1] - a[1] * b[0];
  }
  return 0.5 * std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
}

// A point of the diagram: in recentred coordinates (for areas) and as reported.
struct Node {
  Vec3 local;
  PathPoint point;
};

struct BoundarySegment {
  uint32_t u, v;            // node ids
  uint32_t site_a, site_b;  // site_a < site_b
};

class Builder {
 public:
  Builder(const TriangleMesh& mesh, const DistanceField& field, const TravelCost* travel)
      : mesh_(mesh),
        d_(field.internal_distance.data()),
        label_(field.internal_source.data()),
        travel_(travel),
        edge_node_(3 * static_cast<size_t>(mesh.face_count()), kNoIndex),
        cell_of_site_(field.sources.size(), kNoIndex) {
    if (travel_ != nullptr && travel_->max_slope_deg > 0) slope_deg_ = FaceSlopesDeg(mesh);
  }

  VoronoiDiagram Run() {
    // Cells for every site that labels a vertex, by ascending site.
    std::vector<bool> owns(cell_of_site_.size(), false);
    for (uint32_t v = 0; v < mesh_.vertex_count(); ++v) {
      if (std::isfinite(d_[v]) && label_[v] < owns.size()) owns[label_[v]] = true;
    }
    for (uint32_t s = 0; s < owns.size(); ++s) {
      if (!owns[s]) continue;
      cell_of_site_[s] = static_cast<uint32_t>(out_.cells.size());
      out_.cells.emplace_back().site = s;
    }
    for (uint32_t f = 0; f < mesh_.face_count(); ++f) Face(f);
    Stitch();
    for (const VoronoiCell& c : out_.cells) out_.total_area += c.area;
    std::sort(out_.adjacency.begin(), out_.adjacency.end());
    out_.adjacency.erase(std::unique(out_.adjacency.begin(), out_.adjacency.end()),
                         out_.adjacency.end());
    return std::move(out_);
  }

 private:
  Vec3 Local(uint32_t v) const {
    const double* p = mesh_.positions() + 3 * v;
    return {p[0], p[1], p[2]};
  }

  PathPoint Reported(const Vec3& local, const SurfacePoint& where) const {
    PathPoint p;
    for (int k = 0; k < 3; ++k) p.position[k] = local[k] + mesh_.Center()[k];
    p.where = where;
    return p;
  }

  // The node of the boundary point on the edge of half-edge h (labels differ at its ends), and
  // its parameter from From(h).
  uint32_t EdgeNode(uint32_t h, double* s_local) {
    const uint32_t key = EdgeKey(mesh_, h);
    if (edge_node_[key] == kNoIndex) {
      const uint32_t a = mesh_.From(key), b = mesh_.To(key);
      const double len = mesh_.Length(key);
      // The edge's cost each way in the field's unit (metres, or seconds of travel).
      double ab = len, ba = len;
      TravelCosts(key, &ab, &ba);
      // d_a + s ab = d_b + (1 - s) ba; the exact field keeps the difference within the edge's
      // cost, round-off and approximate fields may not, so s is clamped.
      double s = ab + ba > 0 ? (ba + d_[b] - d_[a]) / (ab + ba) : 0.5;
      s = std::min(1.0, std::max(0.0, s));
      const Vec3 pa = Local(a), pb = Local(b);
      Node n;
      for (int k = 0; k < 3; ++k) n.local[k] = pa[k] + s * (pb[k] - pa[k]);
      n.point =
          Reported(n.local, SurfacePoint::OnEdge(mesh_.FileVertex(a), mesh_.FileVertex(b), s));
      edge_node_[key] = static_cast<uint32_t>(nodes_.size());
      nodes_.push_back(std::move(n));
    }
    const uint32_t node = edge_node_[key];
    const double s = nodes_[node].point.where.t;
    *s_local = key == h ? s : 1 - s;
    return node;
  }

  // With a travel cost, the edge of half-edge `key` walked each way in seconds: its length at the
  // pace of its cheaper side (a walker along it may use either face) and of its slope. Left as
  // metres where the edge cannot be walked (its ends are then unreachable or labelled alike).
  void TravelCosts(uint32_t key, double* ab, double* ba) const {
    if (travel_ == nullptr) return;
    double weight = kUnreachable;
    for (uint32_t h : {key, mesh_.Twin(key)}) {
      if (h == kNoIndex) continue;
      const uint32_t f = TriangleMesh::FaceOf(h);
      double w = travel_->face_weight != nullptr && f < travel_->face_weight->size()
                     ? (*travel_->face_weight)[f]
                     : 1.0;
      if (!slope_deg_.empty() && slope_deg_[f] > travel_->max_slope_deg) w = kUnreachable;
      weight = std::min(weight, w);
    }
    const double len = mesh_.Length(key);
    const double rise = Local(mesh_.To(key))[2] - Local(mesh_.From(key))[2];
    double up = weight * len * SecondsPerMetre(*travel_, rise, len);
    double down = weight * len * SecondsPerMetre(*travel_, -rise, len);
    if (TimesInbound(*travel_)) std::swap(up, down);  // times to reach the sources: walked back
    if (std::isfinite(up) && std::isfinite(down)) *ab = up, *ba = down;
  }

  void AddSegment(uint32_t u, uint32_t v, uint32_t s1, uint32_t s2) {
    const uint32_t a = std::min(s1, s2), b = std::max(s1, s2);
    segments_.push_back({u, v, a, b});
    out_.adjacency.push_back({a, b});
  }

  PathPoint VertexPoint(uint32_t v) const {
    return Reported(Local(v), SurfacePoint::AtVertex(mesh_.FileVertex(v)));
  }

  // A fragment of the cell of `site` in face f with the given corners (node ids or vertices).
  void AddFragment(uint32_t f, uint32_t site, std::vector<Vec3> local,
                   std::vector<PathPoint> polygon) {
    VoronoiCell& cell = out_.cells[cell_of_site_[site]];
    VoronoiFragment& frag = cell.fragments.emplace_back();
    frag.face = f;
    frag.area = PolygonArea(local);
    frag.polygon = std::move(polygon);
    cell.area += frag.area;
  }

  void Face(uint32_t f) {
    uint32_t v[3], l[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = mesh_.FaceVertex(f, k);
      if (!std::isfinite(d_[v[k]])) return;  // unreachable: in no cell
      l[k] = label_[v[k]];
    }
    if (l[0] == l[1] && l[1] == l[2]) {
      VoronoiCell& cell = out_.cells[cell_of_site_[l[0]]];
      cell.whole_faces.push_back(f);
      cell.area += PolygonArea({Local(v[0]), Local(v[1]), Local(v[2])});
      return;
    }
    if (l[0] != l[1] && l[1] != l[2] && l[2] != l[0]) {
      Junction(f, v, l);
      return;
    }
    // Two labels: x is the corner alone with its label; the boundary joins the points on the
    // edges x -> x+1 and x+2 -> x.
    int x = 0;
    while (l[x] == l[(x + 1) % 3] || l[x] == l[(x + 2) % 3]) ++x;
    const int y = (x + 1) % 3, z = (x + 2) % 3;
    double s;
    const uint32_t pn = EdgeNode(3 * f + x, &s), pp = EdgeNode(3 * f + z, &s);
    AddSegment(pn, pp, l[x], l[y]);
    AddFragment(f, l[x], {Local(v[x]), nodes_[pn].local, nodes_[pp].local},
                {VertexPoint(v[x]), nodes_[pn].point, nodes_[pp].point});
    AddFragment(f, l[y], {nodes_[pn].local, Local(v[y]), Local(v[z]), nodes_[pp].local},
                {nodes_[pn].point, VertexPoint(v[y]), VertexPoint(v[z]), nodes_[pp].point});
  }

  // Three labels: the points on the three edges and their barycentre c; the cell of corner k is
  // (v_k, p_k, c, p_{k-1}) with p_k on the edge k -> k+1.
  void Junction(uint32_t f, const uint32_t v[3], const uint32_t l[3]) {
    ++out_.junction_faces;
    uint32_t p[3];
    std::array<double, 3> bary{0, 0, 0};
    Node c;
    c.local = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      double s;
      p[k] = EdgeNode(3 * f + k, &s);
      bary[k] += (1 - s) / 3;
      bary[(k + 1) % 3] += s / 3;
      for (int i = 0; i < 3; ++i) c.local[i] += nodes_[p[k]].local[i] / 3;
    }
    mesh_.SwapCornerOrder(f, &bary);
    c.point = Reported(c.local, SurfacePoint::InFace(f, bary[0], bary[1], bary[2]));
    const uint32_t center = static_cast<uint32_t>(nodes_.size());
    nodes_.push_back(c);
    for (int k = 0; k < 3; ++k) {
      const int next = (k + 1) % 3, prev = (k + 2) % 3;
      AddSegment(center, p[k], l[k], l[next]);
      AddFragment(f, l[k], {Local(v[k]), nodes_[p[k]].local, c.local, nodes_[p[prev]].local},
                  {VertexPoint(v[k]), nodes_[p[k]].point, c.point, nodes_[p[prev]].point});
    }
  }

  // Chains of segments between nodes that are not simply on the way (junctions and ends), then
  // loops.
  void Stitch() {
    std::vector<uint32_t> offset(nodes_.size() + 1, 0), incident(2 * segments_.size());
    for (const BoundarySegment& s : segments_) ++offset[s.u + 1], ++offset[s.v + 1];
    for (size_t i = 0; i < nodes_.size(); ++i) offset[i + 1] += offset[i];
    std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
    for (uint32_t i = 0; i < segments_.size(); ++i) {
      incident[fill[segments_[i].u]++] = i;
      incident[fill[segments_[i].v]++] = i;
    }
    std::vector<bool> used(segments_.size(), false);
    auto degree = [&](uint32_t n) { return offset[n + 1] - offset[n]; };
    auto walk = [&](uint32_t start, uint32_t seg) {
      VoronoiBoundary b;
      b.site_a = segments_[seg].site_a;
      b.site_b = segments_[seg].site_b;
      b.points.push_back(nodes_[start].point);
      uint32_t node = start;
      while (true) {
        used[seg] = true;
        node = segments_[seg].u == node ? segments_[seg].v : segments_[seg].u;
        if (node == start) {
          b.closed = true;
          break;
        }
        b.points.push_back(nodes_[node].point);
        if (degree(node) != 2) break;
        const uint32_t s0 = incident[offset[node]], s1 = incident[offset[node] + 1];
        seg = s0 == seg ? s1 : s0;
        if (used[seg]) break;
      }
      out_.boundaries.push_back(std::move(b));
    };
    for (uint32_t n = 0; n < nodes_.size(); ++n) {
      if (degree(n) == 2) continue;
      for (uint32_t i = offset[n]; i < offset[n + 1]; ++i) {
        if (!used[incident[i]]) walk(n, incident[i]);
      }
    }
    for (uint32_t i = 0; i < segments_.size(); ++i) {
      if (!used[i]) walk(segments_[i].u, i);
    }
  }

  const TriangleMesh& mesh_;
  const double* d_;
  const uint32_t* label_;
  const TravelCost* travel_;         // null: the field is in metres
  std::vector<double> slope_deg_;    // with a travel cost's max_slope_deg: each face's slope
  std::vector<uint32_t> edge_node_;  // per half-edge key
  std::vector<uint32_t> cell_of_site_;
  std::vector<Node> nodes_;
  std::vector<BoundarySegment> segments_;
  VoronoiDiagram out_;
};

}  // namespace

absl::StatusOr<VoronoiDiagram> BuildVoronoi(const TriangleMesh& mesh, const DistanceField& field,
                                            const TravelCost* travel) {
  if (field.internal_distance.size() != mesh.vertex_count() ||
      field.internal_source.size() != mesh.vertex_count()) {
    return absl::InvalidArgumentError("the distance field was not computed on this mesh");
  }
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (std::isfinite(field.internal_distance[v]) &&
        field.internal_source[v] >= field.sources.size()) {
      return absl::InvalidArgumentError(
          "the distance field labels a vertex with an unknown source");
    }
  }
  if (field.travel_epsilon > 0 && travel == nullptr) {
    return absl::InvalidArgumentError(
        "a travel-time field's Voronoi diagram needs its travel cost (seconds, not metres)");
  }
  return Builder(mesh, field, field.travel_epsilon > 0 ? travel : nullptr).Run();
}

}  // namespace geodex
