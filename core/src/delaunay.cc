// The approximate Delaunay triangulation (paper sections 6.3 and 6.4): the shortest candidate edge
// per site pair, traced through the solver's per-vertex origins; XL edges found where a geodesic
// section crosses an edge that none of its endpoints' labels owns.

#include "geodex/delaunay.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <unordered_map>
#include <utility>

#include "absl/strings/str_format.h"
#include "geodex/geodesic_solver.h"

namespace geodex {
namespace {

uint64_t PairKey(uint32_t a, uint32_t b) { return (static_cast<uint64_t>(a) << 32) | b; }

struct Candidate {
  double length;
  uint32_t vertex_a, vertex_b;  // internal ids, labelled site_a < site_b
};

// Whether internal vertex v speaks for its file vertex: TracePathFromVertex starts from the file
// vertex's best copy, so a copy at a non-manifold junction with another label or distance cannot
// be traced and is not used.
bool Traceable(const TriangleMesh& mesh, const DistanceField& field, uint32_t v) {
  const uint32_t f = mesh.FileVertex(v);
  return field.source[f] == field.internal_source[v] &&
         field.distance[f] == field.internal_distance[v];
}

// Per site pair, the shortest candidate (Definition 6); ties go to the first edge in half-edge
// order.
std::vector<std::pair<uint64_t, Candidate>> ShortestCandidates(const TriangleMesh& mesh,
                                                               const DistanceField& field) {
  const double* d = field.internal_distance.data();
  const uint32_t* label = field.internal_source.data();
  std::unordered_map<uint64_t, Candidate> best;
  const uint32_t half_edges = 3 * mesh.face_count();
  for (uint32_t h = 0; h < half_edges; ++h) {
    const uint32_t twin = mesh.Twin(h);
    if (twin != kNoIndex && twin < h) continue;  // each edge once
    uint32_t a = mesh.From(h), b = mesh.To(h);
    if (!std::isfinite(d[a]) || !std::isfinite(d[b]) || label[a] == label[b]) continue;
    if (!Traceable(mesh, field, a) || !Traceable(mesh, field, b)) continue;
    if (label[a] > label[b]) std::swap(a, b);
    const Candidate c{d[a] + mesh.Length(h) + d[b], a, b};
    auto [it, inserted] = best.try_emplace(PairKey(label[a], label[b]), c);
    if (!inserted && c.length < it->second.length) it->second = c;
  }
  std::vector<std::pair<uint64_t, Candidate>> out(best.begin(), best.end());
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  return out;
}

absl::StatusOr<DelaunayEdge> TraceEdge(const TriangleMesh& mesh, const DistanceField& field,
                                       uint64_t pair, const Candidate& c) {
  DelaunayEdge e;
  e.site_a = static_cast<uint32_t>(pair >> 32);
  e.site_b = static_cast<uint32_t>(pair & 0xffffffffu);
  e.vertex_a = mesh.FileVertex(c.vertex_a);
  e.vertex_b = mesh.FileVertex(c.vertex_b);
  e.length = c.length;
  absl::StatusOr<GeodesicPath> pa = TracePathFromVertex(mesh, field, e.vertex_a);
  if (!pa.ok()) return pa.status();
  absl::StatusOr<GeodesicPath> pb = TracePathFromVertex(mesh, field, e.vertex_b);
  if (!pb.ok()) return pb.status();
  if (pa->source != e.site_a || pb->source != e.site_b) {
    return absl::InternalError(absl::StrFormat(
        "the path from vertex %d or %d does not reach its labelled site", e.vertex_a, e.vertex_b));
  }
  e.points.assign(pa->points.rbegin(), pa->points.rend());
  e.edge_start = static_cast<uint32_t>(e.points.size() - 1);
  e.points.insert(e.points.end(), pb->points.begin(), pb->points.end());
  return e;
}

std::pair<uint32_t, uint32_t> Unordered(uint32_t a, uint32_t b) {
  return {std::min(a, b), std::max(a, b)};
}

// Where the geodesic section of `site` (points[begin, end)) crosses the interior of an edge that
// neither endpoint's label owns: an XL edge with that witness.
void FindXlEdges(const DistanceField& field, const DelaunayEdge& e, size_t begin, size_t end,
                 uint32_t site, std::set<std::pair<uint32_t, uint32_t>>* seen,
                 std::vector<XlEdge>* out) {
  for (size_t i = begin; i < end; ++i) {
    const SurfacePoint& w = e.points[i].where;
    if (w.kind != SurfacePoint::Kind::kEdge || !(w.t > 0 && w.t < 1)) continue;
    const uint32_t la = field.source[w.edge_from], lb = field.source[w.edge_to];
    if (la == site || lb == site) continue;
    if (!seen->insert(Unordered(w.edge_from, w.edge_to)).second) continue;
    XlEdge xl;
    xl.vertex_a = w.edge_from;
    xl.vertex_b = w.edge_to;
    xl.site_a = la;
    xl.site_b = lb;
    xl.witness = site;
    xl.point = e.points[i];
    out->push_back(xl);
  }
}

}  // namespace

absl::StatusOr<DelaunayTriangulation> BuildDelaunay(const TriangleMesh& mesh,
                                                    const DistanceField& field) {
  if (field.travel_epsilon > 0) {
    return OptionError("travel",
                       "the geodesic Delaunay triangulation is traced through the exact engine's "
                       "origins; a travel cost has none (Voronoi regions and isolines work)");
  }
  const uint32_t nv = mesh.vertex_count();
  if (field.internal_distance.size() != nv || field.internal_source.size() != nv ||
      field.internal_origin.size() != nv || field.distance.size() != mesh.file_vertex_count() ||
      field.source.size() != mesh.file_vertex_count()) {
    return absl::InvalidArgumentError("the distance field was not computed on this mesh");
  }
  for (uint32_t v = 0; v < nv; ++v) {
    if (std::isfinite(field.internal_distance[v]) &&
        field.internal_source[v] >= field.sources.size()) {
      return absl::InvalidArgumentError(
          "the distance field labels a vertex with an unknown source");
    }
  }
  DelaunayTriangulation out;
  std::vector<DelaunayEdge> all;
  for (const auto& [pair, candidate] : ShortestCandidates(mesh, field)) {
    absl::StatusOr<DelaunayEdge> e = TraceEdge(mesh, field, pair, candidate);
    if (!e.ok()) return e.status();
    all.push_back(*std::move(e));
  }

  // XL edges, witnessed by the geodesic sections (the mesh-edge section crosses no edge).
  std::set<std::pair<uint32_t, uint32_t>> xl;
  for (const DelaunayEdge& e : all) {
    FindXlEdges(field, e, 0, e.edge_start, e.site_a, &xl, &out.xl_edges);
    FindXlEdges(field, e, e.edge_start + 1, e.points.size(), e.site_b, &xl, &out.xl_edges);
  }
  std::set<uint64_t> kept_pairs;
  for (DelaunayEdge& e : all) {
    if (xl.count(Unordered(e.vertex_a, e.vertex_b))) {
      out.removed_edges.push_back(std::move(e));
    } else {
      kept_pairs.insert(PairKey(e.site_a, e.site_b));
      out.edges.push_back(std::move(e));
    }
  }

  // Triangles: the site triples of faces where three cells meet.
  const double* d = field.internal_distance.data();
  const uint32_t* label = field.internal_source.data();
  std::vector<std::array<uint32_t, 3>> triples;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    std::array<uint32_t, 3> t;
    bool reachable = true;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.FaceVertex(f, k);
      reachable = reachable && std::isfinite(d[v]);
      t[k] = label[v];
    }
    if (!reachable || t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) continue;
    std::sort(t.begin(), t.end());
    triples.push_back(t);
  }
  std::sort(triples.begin(), triples.end());
  triples.erase(std::unique(triples.begin(), triples.end()), triples.end());
  for (const auto& t : triples) {
    if (kept_pairs.count(PairKey(t[0], t[1])) && kept_pairs.count(PairKey(t[1], t[2])) &&
        kept_pairs.count(PairKey(t[0], t[2]))) {
      out.triangles.push_back(t);
    }
  }
  return out;
}

}  // namespace geodex
