// The approximate Delaunay triangulation (paper sections 6.3-6.4): planar Delaunay on a flat
// square, edges = Voronoi adjacency and non-crossing (Theorem 7), Definition 6 minimality, XL edges
// on a deliberately coarse mesh and none on a fine one, edge cases.

#include "geodex/delaunay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "geodex/geodesic_solver.h"
#include "geodex/voronoi.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

using SitePairs = std::vector<std::array<uint32_t, 2>>;
using Triples = std::vector<std::array<uint32_t, 3>>;

[[noreturn]] void Abort(const char* what, const absl::Status& status) {
  std::fprintf(stderr, "%s: %s\n", what, std::string(status.message()).c_str());
  std::abort();
}

struct Fixture {
  MeshData data;
  TriangleMesh mesh;
  DistanceField field;
};

Fixture Solve(MeshData data, const std::vector<uint32_t>& sites) {
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  // A helper that returns cannot ASSERT: stop here rather than read an error's value.
  if (!mesh.ok()) Abort("the fixture mesh does not build", mesh.status());
  std::vector<SurfacePoint> sources;
  for (uint32_t v : sites) sources.push_back(SurfacePoint::AtVertex(v));
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sources);
  if (!field.ok()) Abort("the fixture field does not solve", field.status());
  return Fixture{std::move(data), *std::move(mesh), *std::move(field)};
}

// The 60 x 60 unit square, jittered, alternating diagonals; vertex (i, j) is j * 61 + i.
MeshData Square() {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 60;
  spec.alternate_diagonals = true;
  spec.jitter = 0.15;
  return MakeGrid(spec);
}
uint32_t GridVertex(int i, int j) { return static_cast<uint32_t>(j * 61 + i); }
// Two acute Delaunay triangles; and five sites with two obtuse ones. All circumcentres are well
// inside the square.
const std::vector<uint32_t> kFourSites = {GridVertex(20, 14), GridVertex(44, 20),
                                          GridVertex(26, 40), GridVertex(48, 46)};
const std::vector<uint32_t> kFiveSites = {GridVertex(12, 15), GridVertex(47, 10),
                                          GridVertex(28, 33), GridVertex(15, 50),
                                          GridVertex(50, 46)};

double Dist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// The planar Delaunay triangles of `p` (brute force: empty circumcircle) whose circumcentre lies
// in [lo, hi]^2 (all of them when the box is infinite).
Triples PlanarDelaunay(const std::vector<Vec3>& p, double lo, double hi) {
  Triples out;
  const uint32_t n = static_cast<uint32_t>(p.size());
  for (uint32_t a = 0; a < n; ++a) {
    for (uint32_t b = a + 1; b < n; ++b) {
      for (uint32_t c = b + 1; c < n; ++c) {
        const double ax = p[a][0], ay = p[a][1], bx = p[b][0], by = p[b][1], cx = p[c][0],
                     cy = p[c][1];
        const double d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
        if (std::abs(d) < 1e-12) continue;
        const double ux = ((ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) +
                           (cx * cx + cy * cy) * (ay - by)) /
                          d;
        const double uy = ((ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) +
                           (cx * cx + cy * cy) * (bx - ax)) /
                          d;
        const double r = std::hypot(ax - ux, ay - uy);
        bool empty = true;
        for (uint32_t e = 0; e < n; ++e) {
          if (e != a && e != b && e != c && std::hypot(p[e][0] - ux, p[e][1] - uy) < r) {
            empty = false;
          }
        }
        if (empty && ux >= lo && ux <= hi && uy >= lo && uy <= hi) out.push_back({a, b, c});
      }
    }
  }
  return out;
}

// Proper crossing of segments ab and cd in the x-y plane.
bool Cross2d(const std::array<double, 3>& a, const std::array<double, 3>& b,
             const std::array<double, 3>& c, const std::array<double, 3>& d) {
  auto orient = [](const auto& p, const auto& q, const auto& r) {
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
  };
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a),
               o4 = orient(c, d, b);
  return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

// The polyline without the points where it goes straight on (edge crossings of a geodesic on a
// flat mesh), so that a crossing exactly at such a point is still a proper one.
std::vector<std::array<double, 3>> Corners(const std::vector<PathPoint>& x) {
  std::vector<std::array<double, 3>> out;
  for (size_t i = 0; i < x.size(); ++i) {
    const auto& p = x[i].position;
    if (i > 0 && i + 1 < x.size()) {
      const auto& a = out.back();
      const auto& b = x[i + 1].position;
      const double cross = (p[0] - a[0]) * (b[1] - a[1]) - (p[1] - a[1]) * (b[0] - a[0]);
      const double dot = (p[0] - a[0]) * (b[0] - p[0]) + (p[1] - a[1]) * (b[1] - p[1]);
      if (std::abs(cross) <= 1e-12 * Dist(a, b) * Dist(a, b) && dot > 0) continue;
    }
    out.push_back(p);
  }
  return out;
}

bool PolylinesCross(const std::vector<PathPoint>& px, const std::vector<PathPoint>& py) {
  const auto x = Corners(px), y = Corners(py);
  for (size_t i = 0; i + 1 < x.size(); ++i) {
    for (size_t j = 0; j + 1 < y.size(); ++j) {
      if (Cross2d(x[i], x[i + 1], y[j], y[j + 1])) return true;
    }
  }
  return false;
}

// Pairs (i, j) of edges in `edges` whose polylines cross.
int Crossings(const std::vector<DelaunayEdge>& edges) {
  int n = 0;
  for (size_t i = 0; i < edges.size(); ++i) {
    for (size_t j = i + 1; j < edges.size(); ++j)
      n += PolylinesCross(edges[i].points, edges[j].points);
  }
  return n;
}

// What every edge claims: ends at its sites, the mesh-edge section where it says, Definition 6's
// length, and that length minimal over the mesh edges between the two cells.
void CheckEdges(const Fixture& fx, const std::vector<uint32_t>& sites,
                const DelaunayTriangulation& dt) {
  const std::vector<double>& d = fx.field.distance;
  for (const DelaunayEdge& e : dt.edges) {
    EXPECT_LT(e.site_a, e.site_b);
    ASSERT_GE(e.points.size(), 2u);
    EXPECT_LT(Dist(e.points.front().position, VertexPosition(fx.data, sites[e.site_a])), 1e-12);
    EXPECT_LT(Dist(e.points.back().position, VertexPosition(fx.data, sites[e.site_b])), 1e-12);
    ASSERT_LT(e.edge_start + 1, e.points.size());
    const SurfacePoint& wa = e.points[e.edge_start].where;
    const SurfacePoint& wb = e.points[e.edge_start + 1].where;
    ASSERT_EQ(wa.kind, SurfacePoint::Kind::kVertex);
    ASSERT_EQ(wb.kind, SurfacePoint::Kind::kVertex);
    EXPECT_EQ(wa.vertex, e.vertex_a);
    EXPECT_EQ(wb.vertex, e.vertex_b);
    EXPECT_EQ(fx.field.source[e.vertex_a], e.site_a);
    EXPECT_EQ(fx.field.source[e.vertex_b], e.site_b);
    const double edge =
        Dist(VertexPosition(fx.data, e.vertex_a), VertexPosition(fx.data, e.vertex_b));
    EXPECT_NEAR(e.length, d[e.vertex_a] + edge + d[e.vertex_b], 1e-12 * e.length);
    double polyline = 0;
    for (size_t i = 0; i + 1 < e.points.size(); ++i) {
      polyline += Dist(e.points[i].position, e.points[i + 1].position);
    }
    EXPECT_NEAR(polyline, e.length, 1e-9 * e.length);
    for (uint32_t f = 0; f < fx.data.face_count(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t u = fx.data.faces[3 * f + k], w = fx.data.faces[3 * f + (k + 1) % 3];
        const std::set<uint32_t> labels = {fx.field.source[u], fx.field.source[w]};
        if (labels != std::set<uint32_t>{e.site_a, e.site_b}) continue;
        const double candidate =
            d[u] + Dist(VertexPosition(fx.data, u), VertexPosition(fx.data, w)) + d[w];
        EXPECT_GE(candidate, e.length * (1 - 1e-12));
      }
    }
  }
}

std::vector<Vec3> SitePositions(const Fixture& fx, const std::vector<uint32_t>& sites) {
  std::vector<Vec3> p;
  for (uint32_t v : sites) p.push_back(VertexPosition(fx.data, v));
  return p;
}

TEST(DelaunayTest, FlatSquareGivesThePlanarDelaunayTriangulation) {
  for (const auto* sites : {&kFourSites, &kFiveSites}) {
    const Fixture fx = Solve(Square(), *sites);
    absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
    ASSERT_TRUE(dt.ok()) << dt.status();
    CheckEdges(fx, *sites, *dt);
    const std::vector<Vec3> p = SitePositions(fx, *sites);
    // Every triangle found is a planar Delaunay triangle; every planar one whose circumcentre
    // (the Voronoi vertex) is well inside the square is found.
    const Triples all = PlanarDelaunay(p, -1e9, 1e9), inside = PlanarDelaunay(p, 0.05, 0.95);
    for (const auto& t : dt->triangles) {
      EXPECT_TRUE(std::count(all.begin(), all.end(), t)) << t[0] << " " << t[1] << " " << t[2];
    }
    for (const auto& t : inside) {
      EXPECT_TRUE(std::count(dt->triangles.begin(), dt->triangles.end(), t))
          << t[0] << " " << t[1] << " " << t[2];
    }
    EXPECT_EQ(dt->triangles.size(), sites->size() == 4 ? 2u : 4u);
  }
}

TEST(DelaunayTest, EdgesJoinAdjacentCellsAndDoNotCross) {
  for (const auto* sites : {&kFourSites, &kFiveSites}) {
    const Fixture fx = Solve(Square(), *sites);
    absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
    ASSERT_TRUE(dt.ok()) << dt.status();
    absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
    ASSERT_TRUE(vd.ok()) << vd.status();
    // Theorem 7: joined iff the cells share a boundary; no two edges cross.
    SitePairs pairs;
    for (const DelaunayEdge& e : dt->edges) pairs.push_back({e.site_a, e.site_b});
    EXPECT_EQ(pairs, vd->adjacency);
    EXPECT_EQ(Crossings(dt->edges), 0);
    // A fine flat mesh has no XL edges to find.
    EXPECT_TRUE(dt->xl_edges.empty());
    EXPECT_TRUE(dt->removed_edges.empty());
  }
}

TEST(DelaunayTest, CurvedMeshEdgesAreConsistent) {
  // bunny-npm is closed and of genus 0.
  absl::StatusOr<MeshData> data = LoadTestMeshData("bunny-npm.off");
  ASSERT_TRUE(data.ok()) << data.status();
  const std::vector<uint32_t> sites = {0, 300, 600, 900, 1200, 1500};
  const Fixture fx = Solve(*data, sites);
  absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
  ASSERT_TRUE(dt.ok()) << dt.status();
  CheckEdges(fx, sites, *dt);
  absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
  ASSERT_TRUE(vd.ok()) << vd.status();
  SitePairs pairs;
  for (const auto* list : {&dt->edges, &dt->removed_edges}) {
    for (const DelaunayEdge& e : *list) pairs.push_back({e.site_a, e.site_b});
  }
  std::sort(pairs.begin(), pairs.end());
  EXPECT_EQ(pairs, vd->adjacency);
  EXPECT_FALSE(dt->triangles.empty());
  // Six disk-shaped cells on a sphere-like surface, three meeting at each junction: Euler gives
  // 2 * 6 - 4 = 8 triangles and 3 * 6 - 6 = 12 edges.
  EXPECT_EQ(dt->triangles.size(), 8u);
  EXPECT_EQ(dt->edges.size(), 12u);
}

// The XL fixture, planar: u = (0,0) and w = (10,0) joined by a long edge, c = (5,1) above its
// middle, z = (5,-1) below and d = (5,-3.5) at the bottom. Sites A = u, B = w, C = c, D = d. The
// middle of u-w is 1 from C but 5 from A and B, while u and w are labelled A and B: u-w is an XL
// edge. z is C's (2 < 2.5 to D), and the Delaunay edge C-z-d-D's geodesic C -> z crosses u-w.
MeshData XlFixture() {
  MeshData m;
  m.positions = {0, 0, 0, 10, 0, 0, 5, 1, 0, 5, -1, 0, 5, -3.5, 0};  // u w c z d
  m.faces = {0, 1, 2, 0, 3, 1, 0, 4, 3, 3, 4, 1};
  return m;
}

TEST(DelaunayTest, XlEdgeOnACoarseMeshIsFoundAndItsDelaunayEdgeRemoved) {
  const std::vector<uint32_t> sites = {0, 1, 2, 4};  // A B C D
  const Fixture fx = Solve(XlFixture(), sites);
  ASSERT_EQ(fx.field.source[3], 2u);
  absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
  ASSERT_TRUE(dt.ok()) << dt.status();
  CheckEdges(fx, sites, *dt);
  ASSERT_EQ(dt->xl_edges.size(), 1u);
  const XlEdge& xl = dt->xl_edges[0];
  EXPECT_EQ(std::set<uint32_t>({xl.vertex_a, xl.vertex_b}), std::set<uint32_t>({0, 1}));
  EXPECT_EQ(std::set<uint32_t>({xl.site_a, xl.site_b}), std::set<uint32_t>({0, 1}));
  EXPECT_EQ(xl.witness, 2u);
  EXPECT_LT(Dist(xl.point.position, {5, 0, 0}), 1e-12);
  // A-u-w-B is removed; it would cross C-z-d-D.
  ASSERT_EQ(dt->removed_edges.size(), 1u);
  const DelaunayEdge& removed = dt->removed_edges[0];
  EXPECT_EQ(removed.site_a, 0u);
  EXPECT_EQ(removed.site_b, 1u);
  std::vector<DelaunayEdge> with_removed = dt->edges;
  with_removed.push_back(removed);
  EXPECT_EQ(Crossings(with_removed), 1);
  EXPECT_EQ(Crossings(dt->edges), 0);
  SitePairs pairs;
  for (const DelaunayEdge& e : dt->edges) pairs.push_back({e.site_a, e.site_b});
  EXPECT_EQ(pairs, (SitePairs{{0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}));
  // The face u w c has three labels, but its triangle A B C lost a side.
  EXPECT_EQ(dt->triangles, (Triples{{0, 2, 3}, {1, 2, 3}}));
}

TEST(DelaunayTest, FineMeshOfTheXlDomainHasNoXlEdges) {
  // [0,10] x [-3.5,1] in 0.1 cells with the same four sites: the exact cells of A and B do not
  // meet, and the approximation agrees.
  GridSpec spec;
  spec.cells_x = 100;
  spec.cells_y = 45;
  spec.width = 10;
  spec.height = 4.5;
  spec.alternate_diagonals = true;
  MeshData m = MakeGrid(spec);
  for (size_t i = 1; i < m.positions.size(); i += 3) m.positions[i] -= 3.5;
  auto vertex = [](int i, int j) { return static_cast<uint32_t>(j * 101 + i); };
  const std::vector<uint32_t> sites = {vertex(0, 35), vertex(100, 35), vertex(50, 45),
                                       vertex(50, 0)};
  const Fixture fx = Solve(m, sites);
  absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
  ASSERT_TRUE(dt.ok()) << dt.status();
  CheckEdges(fx, sites, *dt);
  EXPECT_TRUE(dt->xl_edges.empty());
  EXPECT_TRUE(dt->removed_edges.empty());
  SitePairs pairs;
  for (const DelaunayEdge& e : dt->edges) pairs.push_back({e.site_a, e.site_b});
  EXPECT_EQ(pairs, (SitePairs{{0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}));
  EXPECT_EQ(dt->triangles, (Triples{{0, 2, 3}, {1, 2, 3}}));
  EXPECT_EQ(Crossings(dt->edges), 0);
}

TEST(DelaunayTest, EdgeCases) {
  {
    // A single site: nothing to join.
    const Fixture fx = Solve(Square(), {GridVertex(30, 30)});
    absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
    ASSERT_TRUE(dt.ok()) << dt.status();
    EXPECT_TRUE(dt->edges.empty());
    EXPECT_TRUE(dt->triangles.empty());
    EXPECT_TRUE(dt->xl_edges.empty());
  }
  {
    // Two sites on one vertex: the second owns nothing and gets no edge.
    const std::vector<uint32_t> sites = {GridVertex(30, 30), GridVertex(30, 30), GridVertex(5, 5)};
    const Fixture fx = Solve(Square(), sites);
    absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
    ASSERT_TRUE(dt.ok()) << dt.status();
    CheckEdges(fx, sites, *dt);
    ASSERT_EQ(dt->edges.size(), 1u);
    EXPECT_EQ(dt->edges[0].site_b, 2u);
  }
  {
    // Sites at two corners of one face: the Delaunay edge is that mesh edge.
    const std::vector<uint32_t> sites = {GridVertex(30, 30), GridVertex(31, 30)};
    const Fixture fx = Solve(Square(), sites);
    absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
    ASSERT_TRUE(dt.ok()) << dt.status();
    CheckEdges(fx, sites, *dt);
    ASSERT_EQ(dt->edges.size(), 1u);
    EXPECT_EQ(dt->edges[0].points.size(), 2u);
    EXPECT_EQ(dt->edges[0].vertex_a, sites[0]);
    EXPECT_EQ(dt->edges[0].vertex_b, sites[1]);
  }
  {
    // An unreachable second square: edges only between the sites of the first.
    MeshData a = Square(), b = Square();
    const uint32_t offset = static_cast<uint32_t>(a.vertex_count());
    for (size_t i = 0; i < b.positions.size(); ++i) {
      a.positions.push_back(b.positions[i] + (i % 3 == 0 ? 2 : 0));
    }
    for (uint32_t v : b.faces) a.faces.push_back(v + offset);
    const std::vector<uint32_t> sites = kFourSites;
    const Fixture fx = Solve(a, sites);
    absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
    ASSERT_TRUE(dt.ok()) << dt.status();
    CheckEdges(fx, sites, *dt);
    EXPECT_EQ(dt->edges.size(), 5u);
    EXPECT_EQ(dt->triangles.size(), 2u);

    DistanceField wrong = fx.field;
    wrong.internal_origin.clear();
    EXPECT_EQ(BuildDelaunay(fx.mesh, wrong).status().code(), absl::StatusCode::kInvalidArgument);
  }
}

}  // namespace
}  // namespace geodex
