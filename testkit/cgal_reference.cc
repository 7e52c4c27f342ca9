#include "testkit/cgal_reference.h"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_shortest_path.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>

namespace geodex {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using CgalMesh = CGAL::Surface_mesh<Point3>;
using Traits = CGAL::Surface_mesh_shortest_path_traits<Kernel, CgalMesh>;
using ShortestPath = CGAL::Surface_mesh_shortest_path<Traits>;
using VertexIndex = CgalMesh::Vertex_index;
using FaceIndex = CgalMesh::Face_index;
using HalfedgeIndex = CgalMesh::Halfedge_index;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kAbsent = std::numeric_limits<uint32_t>::max();

// Barycentric coordinate k of a CGAL face location belongs to source(next^k(halfedge(f))) (see
// CGAL::Surface_mesh_shortest_paths_3::internal::edge_index and face_location()). Returns the
// CGAL-ordered coordinates of the point whose weight on CGAL vertex w is weight(w).
template <typename WeightOf>
Traits::Barycentric_coordinates CgalBary(const CgalMesh& m, FaceIndex f, WeightOf weight) {
  HalfedgeIndex h = m.halfedge(f);
  double c[3];
  for (int k = 0; k < 3; ++k) {
    c[k] = weight(m.source(h));
    h = m.next(h);
  }
  return Traits().construct_barycentric_coordinates_object()(c[0], c[1], c[2]);
}

double MsSince(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

}  // namespace

std::vector<double> CgalDistances(const MeshData& data, const std::vector<SurfacePoint>& sources,
                                  CgalTiming* timing) {
  const auto start = std::chrono::steady_clock::now();
  const size_t nv = data.vertex_count(), nf = data.face_count();
  for (uint32_t v : data.faces) {
    if (v >= nv) return {};
  }
  // The working copy: file vertices and faces, plus one vertex per edge source and the halves of
  // the faces split there (see below).
  std::vector<double> positions = data.positions;
  std::vector<std::array<uint32_t, 3>> faces(nf);
  for (size_t f = 0; f < nf; ++f) {
    faces[f] = {data.faces[3 * f], data.faces[3 * f + 1], data.faces[3 * f + 2]};
  }
  std::vector<uint8_t> face_split(nf, 0);
  // Vertex ids (working numbering) of the sources that are vertices after edge splitting.
  std::vector<uint32_t> vertex_sources;

  // Edge sources: CGAL 5.5 (Debian 12) mis-handles source points on an edge: expand_edge_root()
  // re-reads the edge parameter mirrored (t becomes 1 - t) and seeds no cone towards the edge's
  // end points (fixed upstream by CGAL pull request #6739, CGAL 5.6). So an edge source is made a
  // vertex instead: the point becomes a new vertex splitting its edge and the (one or two) faces
  // on it into coplanar halves. The surface, hence every geodesic distance, is unchanged.
  for (const SurfacePoint& p : sources) {
    if (p.kind == SurfacePoint::Kind::kVertex) {
      if (p.vertex >= nv) return {};
      vertex_sources.push_back(p.vertex);
      continue;
    }
    if (p.kind != SurfacePoint::Kind::kEdge) continue;
    const uint32_t a = p.edge_from, b = p.edge_to;
    if (a >= nv || b >= nv || !(p.t >= 0 && p.t <= 1)) return {};
    if (p.t == 0 || p.t == 1) {
      vertex_sources.push_back(p.t == 0 ? a : b);
      continue;
    }
    const uint32_t q = static_cast<uint32_t>(positions.size() / 3);
    for (int k = 0; k < 3; ++k) {
      positions.push_back((1 - p.t) * data.positions[3 * a + k] + p.t * data.positions[3 * b + k]);
    }
    bool found = false;
    const size_t face_count = faces.size();
    for (size_t f = 0; f < face_count; ++f) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t u = faces[f][k], w = faces[f][(k + 1) % 3], o = faces[f][(k + 2) % 3];
        if ((u == a && w == b) || (u == b && w == a)) {
          faces[f] = {u, q, o};  // both halves keep the face's orientation
          faces.push_back({q, w, o});
          if (f < nf) face_split[f] = 1;
          found = true;
          break;
        }
      }
    }
    if (!found) return {};  // no such edge
    vertex_sources.push_back(q);
  }

  // Only referenced vertices go into CGAL's mesh (an isolated vertex has no halfedge and breaks
  // CGAL's vertex queries).
  const size_t working_vertices = positions.size() / 3;
  std::vector<uint32_t> to_cgal(working_vertices, kAbsent);
  for (const auto& f : faces) {
    for (uint32_t v : f) to_cgal[v] = 0;
  }
  CgalMesh m;
  std::vector<uint32_t> cgal_to_file;  // kAbsent for the vertices added at edge sources
  for (uint32_t v = 0; v < working_vertices; ++v) {
    if (to_cgal[v] == kAbsent) continue;
    to_cgal[v] = static_cast<uint32_t>(
        m.add_vertex(Point3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2])));
    cgal_to_file.push_back(v < nv ? v : kAbsent);
  }
  std::vector<FaceIndex> cgal_faces(faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    cgal_faces[f] = m.add_face(VertexIndex(to_cgal[faces[f][0]]), VertexIndex(to_cgal[faces[f][1]]),
                               VertexIndex(to_cgal[faces[f][2]]));
    if (cgal_faces[f] == CgalMesh::null_face()) return {};  // non-manifold or badly oriented
  }

  ShortestPath shortest_paths(m);
  for (uint32_t v : vertex_sources) {
    if (to_cgal[v] == kAbsent) return {};  // an isolated vertex
    shortest_paths.add_source_point(VertexIndex(to_cgal[v]));
  }
  // Face sources: a CGAL face location, the barycentrics permuted from the file's corner order to
  // CGAL's (coordinate k belongs to source(next^k(halfedge(f))), see
  // Surface_mesh_shortest_paths_3::internal::edge_index and face_location()).
  for (const SurfacePoint& p : sources) {
    if (p.kind != SurfacePoint::Kind::kFace) continue;
    if (p.face >= nf || face_split[p.face]) return {};  // unknown, or split by an edge source
    const std::array<uint32_t, 3>& c = faces[p.face];
    auto weight = [&](VertexIndex w) {
      for (int k = 0; k < 3; ++k) {
        if (to_cgal[c[k]] == static_cast<uint32_t>(w)) return p.bary[k];
      }
      return std::numeric_limits<double>::quiet_NaN();  // cannot happen: w is a corner
    };
    shortest_paths.add_source_point(cgal_faces[p.face], CgalBary(m, cgal_faces[p.face], weight));
  }
  const auto solve_start = std::chrono::steady_clock::now();
  shortest_paths.build_sequence_tree();
  const auto query_start = std::chrono::steady_clock::now();

  std::vector<double> distance(nv, kInf);
  for (VertexIndex v : m.vertices()) {
    const uint32_t file_vertex = cgal_to_file[static_cast<uint32_t>(v)];
    if (file_vertex == kAbsent) continue;
    const auto result = shortest_paths.shortest_distance_to_source_points(v);
    // CGAL reports a vertex no source reaches (another component) with a negative distance and
    // source_points_end(): that is +inf here.
    if (result.second == shortest_paths.source_points_end() || !(result.first >= 0)) continue;
    distance[file_vertex] = result.first;
  }
  if (timing != nullptr) {
    timing->setup_ms = std::chrono::duration<double, std::milli>(solve_start - start).count();
    timing->solve_ms = std::chrono::duration<double, std::milli>(query_start - solve_start).count();
    timing->query_ms = MsSince(query_start);
  }
  return distance;
}

std::vector<std::array<uint32_t, 3>> CgalDelaunayTriangles(
    const std::vector<std::array<double, 2>>& points) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Vb = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, K>;
  using Tds = CGAL::Triangulation_data_structure_2<Vb>;
  using Delaunay = CGAL::Delaunay_triangulation_2<K, Tds>;
  Delaunay dt;
  for (uint32_t i = 0; i < points.size(); ++i) {
    const size_t before = dt.number_of_vertices();
    Delaunay::Vertex_handle v = dt.insert(K::Point_2(points[i][0], points[i][1]));
    if (dt.number_of_vertices() > before) v->info() = i;  // a duplicate keeps the first index
  }
  std::vector<std::array<uint32_t, 3>> out;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    std::array<uint32_t, 3> t = {f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace geodex
