// The approximate Voronoi diagram (paper section 6.2): boundaries near the Euclidean bisectors on a
// flat square, cells partition the reachable surface (areas, face membership), cells connected
// (Theorem 5), adjacency, closed boundaries on a closed mesh, edge cases.

#include "geodex/voronoi.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <set>

#include "geodex/delaunay.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geometry_queries.h"
#include "geodex/travel_cost.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

using SitePairs = std::vector<std::array<uint32_t, 2>>;

struct Fixture {
  MeshData data;
  TriangleMesh mesh;
  DistanceField field;
};

Fixture Solve(MeshData data, const std::vector<uint32_t>& sites) {
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  std::vector<SurfacePoint> sources;
  for (uint32_t v : sites) sources.push_back(SurfacePoint::AtVertex(v));
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sources);
  EXPECT_TRUE(field.ok()) << field.status();
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
// Five sites in general position, Voronoi vertices well inside the square.
const std::vector<uint32_t> kFiveSites = {GridVertex(12, 15), GridVertex(47, 10),
                                          GridVertex(28, 33), GridVertex(15, 50),
                                          GridVertex(50, 46)};

double FaceArea(const MeshData& m, uint32_t f) {
  const Vec3 a = VertexPosition(m, m.faces[3 * f]), b = VertexPosition(m, m.faces[3 * f + 1]),
             c = VertexPosition(m, m.faces[3 * f + 2]);
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return 0.5 *
         std::sqrt(std::pow(u[1] * v[2] - u[2] * v[1], 2) + std::pow(u[2] * v[0] - u[0] * v[2], 2) +
                   std::pow(u[0] * v[1] - u[1] * v[0], 2));
}

// Every face is in exactly the cells of the labels at its vertices: whole when it has one label,
// one fragment per label otherwise; areas add up per face and in total.
void CheckPartition(const Fixture& fx, const VoronoiDiagram& vd) {
  const uint32_t nf = static_cast<uint32_t>(fx.data.face_count());
  std::vector<std::set<uint32_t>> cells_of_face(nf);
  std::vector<double> area_of_face(nf, 0);
  std::vector<int> whole(nf, 0);
  for (const VoronoiCell& cell : vd.cells) {
    double area = 0;
    for (uint32_t f : cell.whole_faces) {
      EXPECT_TRUE(cells_of_face[f].insert(cell.site).second);
      ++whole[f];
      area_of_face[f] += FaceArea(fx.data, f);
      area += FaceArea(fx.data, f);
    }
    for (const VoronoiFragment& frag : cell.fragments) {
      EXPECT_TRUE(cells_of_face[frag.face].insert(cell.site).second) << "two fragments, one face";
      area_of_face[frag.face] += frag.area;
      area += frag.area;
      EXPECT_GE(frag.polygon.size(), 3u);
      EXPECT_LE(frag.polygon.size(), 4u);
      // Its mesh-vertex corners are exactly the face's vertices of this cell, and its area is the
      // polygon's.
      std::set<uint32_t> corners, own;
      for (const PathPoint& p : frag.polygon) {
        if (p.where.kind == SurfacePoint::Kind::kVertex) corners.insert(p.where.vertex);
      }
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = fx.data.faces[3 * frag.face + k];
        if (fx.field.source[v] == cell.site) own.insert(v);
      }
      EXPECT_EQ(corners, own) << "face " << frag.face;
      Vec3 twice{0, 0, 0};
      for (size_t i = 1; i + 1 < frag.polygon.size(); ++i) {
        const auto& o = frag.polygon[0].position;
        const auto& a = frag.polygon[i].position;
        const auto& b = frag.polygon[i + 1].position;
        const Vec3 u{a[0] - o[0], a[1] - o[1], a[2] - o[2]},
            w{b[0] - o[0], b[1] - o[1], b[2] - o[2]};
        twice[0] += u[1] * w[2] - u[2] * w[1];
        twice[1] += u[2] * w[0] - u[0] * w[2];
        twice[2] += u[0] * w[1] - u[1] * w[0];
      }
      EXPECT_NEAR(frag.area, 0.5 * std::hypot(twice[0], twice[1], twice[2]),
                  1e-9 * FaceArea(fx.data, frag.face));
    }
    EXPECT_NEAR(area, cell.area, 1e-12 * (1 + area));
  }
  double reachable_area = 0, total = 0;
  std::set<uint32_t> owners;
  for (uint32_t v = 0; v < fx.data.vertex_count(); ++v) {
    if (std::isfinite(fx.field.distance[v])) owners.insert(fx.field.source[v]);
  }
  for (uint32_t f = 0; f < nf; ++f) {
    std::set<uint32_t> labels;
    bool reachable = true;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = fx.data.faces[3 * f + k];
      reachable = reachable && std::isfinite(fx.field.distance[v]);
      labels.insert(fx.field.source[v]);
    }
    if (!reachable) {
      EXPECT_TRUE(cells_of_face[f].empty()) << "face " << f;
      continue;
    }
    EXPECT_EQ(cells_of_face[f], labels) << "face " << f;
    EXPECT_EQ(whole[f], labels.size() == 1 ? 1 : 0) << "face " << f;
    EXPECT_NEAR(area_of_face[f], FaceArea(fx.data, f), 1e-12 + 1e-9 * FaceArea(fx.data, f));
    reachable_area += FaceArea(fx.data, f);
  }
  for (const VoronoiCell& cell : vd.cells) total += cell.area;
  EXPECT_NEAR(vd.total_area, total, 1e-12 * total);
  EXPECT_NEAR(vd.total_area, reachable_area, 1e-9 * reachable_area);
  // One cell per site that owns a vertex, ascending.
  std::set<uint32_t> cell_sites;
  for (const VoronoiCell& cell : vd.cells) cell_sites.insert(cell.site);
  EXPECT_EQ(cell_sites, owners);
  EXPECT_EQ(vd.cells.size(), owners.size());
  EXPECT_TRUE(std::is_sorted(vd.cells.begin(), vd.cells.end(),
                             [](const auto& a, const auto& b) { return a.site < b.site; }));
}

// Every boundary point is where it claims to be, and separates the right labels.
void CheckBoundaries(const Fixture& fx, const VoronoiDiagram& vd) {
  std::set<std::array<uint32_t, 2>> pairs;
  for (const VoronoiBoundary& b : vd.boundaries) {
    EXPECT_LT(b.site_a, b.site_b);
    EXPECT_GE(b.points.size(), 2u);
    pairs.insert({b.site_a, b.site_b});
    for (const PathPoint& p : b.points) {
      if (p.where.kind == SurfacePoint::Kind::kEdge) {
        const std::set<uint32_t> labels = {fx.field.source[p.where.edge_from],
                                           fx.field.source[p.where.edge_to]};
        EXPECT_EQ(labels, (std::set<uint32_t>{b.site_a, b.site_b}));
        const Vec3 a = VertexPosition(fx.data, p.where.edge_from);
        const Vec3 c = VertexPosition(fx.data, p.where.edge_to);
        for (int k = 0; k < 3; ++k) {
          EXPECT_NEAR(p.position[k], a[k] + p.where.t * (c[k] - a[k]), 1e-12);
        }
      } else {
        ASSERT_EQ(p.where.kind, SurfacePoint::Kind::kFace);  // a junction
        const uint32_t f = p.where.face;
        Vec3 q{0, 0, 0};
        for (int k = 0; k < 3; ++k) {
          const Vec3 v = VertexPosition(fx.data, fx.data.faces[3 * f + k]);
          for (int i = 0; i < 3; ++i) q[i] += p.where.bary[k] * v[i];
        }
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(p.position[i], q[i], 1e-12);
      }
    }
  }
  EXPECT_EQ(SitePairs(pairs.begin(), pairs.end()), vd.adjacency);
}

// Theorem 5: each cell's faces are connected through edges that have an endpoint in the cell.
int DisconnectedCells(const Fixture& fx, const VoronoiDiagram& vd) {
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> faces_of_edge;
  for (uint32_t f = 0; f < fx.data.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = fx.data.faces[3 * f + k], b = fx.data.faces[3 * f + (k + 1) % 3];
      faces_of_edge[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  }
  int disconnected = 0;
  for (const VoronoiCell& cell : vd.cells) {
    std::map<uint32_t, uint32_t> parent;
    for (uint32_t f : cell.whole_faces) parent[f] = f;
    for (const VoronoiFragment& frag : cell.fragments) parent[frag.face] = frag.face;
    auto find = [&](uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const auto& [edge, faces] : faces_of_edge) {
      if (fx.field.source[edge.first] != cell.site && fx.field.source[edge.second] != cell.site) {
        continue;
      }
      for (size_t i = 1; i < faces.size(); ++i) {
        if (parent.count(faces[0]) && parent.count(faces[i]))
          parent[find(faces[i])] = find(faces[0]);
      }
    }
    std::set<uint32_t> roots;
    for (const auto& [f, p] : parent) roots.insert(find(f));
    if (roots.size() != 1) ++disconnected;
  }
  return disconnected;
}

TEST(VoronoiTest, BoundariesLieNearTheBisectorsOnAFlatSquare) {
  const Fixture fx = Solve(Square(), kFiveSites);
  absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
  ASSERT_TRUE(vd.ok()) << vd.status();
  CheckBoundaries(fx, *vd);
  const double h = fx.mesh.MaxEdgeLength();
  double worst = 0, sum = 0;
  size_t points = 0;
  for (const VoronoiBoundary& b : vd->boundaries) {
    const Vec3 sa = VertexPosition(fx.data, kFiveSites[b.site_a]);
    const Vec3 sb = VertexPosition(fx.data, kFiveSites[b.site_b]);
    const double gap = std::hypot(sa[0] - sb[0], sa[1] - sb[1]);
    for (const PathPoint& p : b.points) {
      const double da = std::hypot(p.position[0] - sa[0], p.position[1] - sa[1]);
      const double db = std::hypot(p.position[0] - sb[0], p.position[1] - sb[1]);
      const double to_bisector = std::abs(da * da - db * db) / (2 * gap);
      worst = std::max(worst, to_bisector);
      sum += to_bisector;
      ++points;
    }
  }
  EXPECT_GT(points, 200u);
  // Any point of a straddling edge is within h of the bisector. The paper's rule assumes the
  // distance grows at unit rate along the edge, which is off by a fraction of h when the edge is
  // oblique to the sites' directions: measured 0.23 h worst, 0.05 h mean here (splitting every
  // edge at its midpoint instead: 0.42 h and 0.13 h).
  EXPECT_LT(worst, 0.3 * h);
  EXPECT_LT(sum / points, 0.08 * h);
  // Four Voronoi vertices inside the square: four junction faces (a junction can straddle two
  // faces when the vertex is near an edge).
  EXPECT_GE(vd->junction_faces, 4u);
  EXPECT_LE(vd->junction_faces, 8u);
}

TEST(VoronoiTest, CellsPartitionTheSquareLikeTheEuclideanCells) {
  const Fixture fx = Solve(Square(), kFiveSites);
  absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
  ASSERT_TRUE(vd.ok()) << vd.status();
  CheckPartition(fx, *vd);
  EXPECT_NEAR(vd->total_area, 1.0, 1e-12);
  ASSERT_EQ(vd->cells.size(), 5u);
  // Theorem 5 (the Delaunay test checks that this mesh and these sites have no XL edges found).
  EXPECT_EQ(DisconnectedCells(fx, *vd), 0);
  // Euclidean cell areas and adjacency by sampling the square.
  const int n = 600;
  std::vector<double> area(5, 0);
  std::set<std::array<uint32_t, 2>> adjacent;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double x = (i + 0.5) / n, y = (j + 0.5) / n;
      std::vector<std::pair<double, uint32_t>> d;
      for (uint32_t s = 0; s < 5; ++s) {
        const Vec3 p = VertexPosition(fx.data, kFiveSites[s]);
        d.push_back({std::hypot(x - p[0], y - p[1]), s});
      }
      std::sort(d.begin(), d.end());
      area[d[0].second] += 1.0 / (n * n);
      if (d[1].first - d[0].first < 2.0 / n) {
        adjacent.insert({std::min(d[0].second, d[1].second), std::max(d[0].second, d[1].second)});
      }
    }
  }
  for (const VoronoiCell& cell : vd->cells) {
    EXPECT_NEAR(cell.area, area[cell.site], 0.01) << "site " << cell.site;
  }
  EXPECT_EQ(SitePairs(adjacent.begin(), adjacent.end()), vd->adjacency);
}

TEST(VoronoiTest, CellsOnACurvedClosedMeshAreConnectedAndBoundariesClosed) {
  absl::StatusOr<MeshData> data = LoadTestMeshData("kitten.off");
  ASSERT_TRUE(data.ok()) << data.status();
  {
    const Fixture fx = Solve(*data, {0, 400, 900, 1300, 1800, 2300});
    absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
    ASSERT_TRUE(vd.ok()) << vd.status();
    CheckPartition(fx, *vd);
    CheckBoundaries(fx, *vd);
    // Theorem 5's premise, as far as the Delaunay edges can tell: no XL edges.
    absl::StatusOr<DelaunayTriangulation> dt = BuildDelaunay(fx.mesh, fx.field);
    ASSERT_TRUE(dt.ok()) << dt.status();
    EXPECT_TRUE(dt->xl_edges.empty());
    EXPECT_EQ(DisconnectedCells(fx, *vd), 0);
    // Junctions end the boundaries; on a closed mesh nothing else does.
    for (const VoronoiBoundary& b : vd->boundaries) {
      if (b.closed) continue;
      EXPECT_EQ(b.points.front().where.kind, SurfacePoint::Kind::kFace);
      EXPECT_EQ(b.points.back().where.kind, SurfacePoint::Kind::kFace);
    }
  }
  // Two sites on a closed mesh: only loops between them.
  const Fixture fx = Solve(*data, {0, 1300});
  absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
  ASSERT_TRUE(vd.ok()) << vd.status();
  CheckPartition(fx, *vd);
  CheckBoundaries(fx, *vd);
  EXPECT_EQ(vd->junction_faces, 0u);
  ASSERT_FALSE(vd->boundaries.empty());
  for (const VoronoiBoundary& b : vd->boundaries) {
    EXPECT_TRUE(b.closed);
    EXPECT_GE(b.points.size(), 3u);
  }
  EXPECT_EQ(vd->adjacency, (SitePairs{{0, 1}}));
}

TEST(VoronoiTest, SingleSiteOwnsEverything) {
  const Fixture fx = Solve(Square(), {GridVertex(30, 30)});
  absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
  ASSERT_TRUE(vd.ok()) << vd.status();
  CheckPartition(fx, *vd);
  ASSERT_EQ(vd->cells.size(), 1u);
  EXPECT_EQ(vd->cells[0].whole_faces.size(), fx.data.face_count());
  EXPECT_TRUE(vd->cells[0].fragments.empty());
  EXPECT_TRUE(vd->boundaries.empty());
  EXPECT_TRUE(vd->adjacency.empty());
}

TEST(VoronoiTest, TwoSitesOnOneVertexAndSitesSharingAFace) {
  {
    // The second site at the same vertex owns nothing: no cell.
    const Fixture fx = Solve(Square(), {GridVertex(30, 30), GridVertex(30, 30), GridVertex(5, 5)});
    absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
    ASSERT_TRUE(vd.ok()) << vd.status();
    CheckPartition(fx, *vd);
    CheckBoundaries(fx, *vd);
    EXPECT_EQ(vd->cells.size(), 2u);
  }
  // Sites at two corners of one face (and a third one elsewhere): a boundary right between them.
  const Fixture fx = Solve(Square(), {GridVertex(30, 30), GridVertex(31, 30), GridVertex(10, 40)});
  absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
  ASSERT_TRUE(vd.ok()) << vd.status();
  CheckPartition(fx, *vd);
  CheckBoundaries(fx, *vd);
  EXPECT_EQ(vd->cells.size(), 3u);
  EXPECT_EQ(DisconnectedCells(fx, *vd), 0);
  EXPECT_TRUE(
      std::count(vd->adjacency.begin(), vd->adjacency.end(), std::array<uint32_t, 2>{0, 1}) == 1);
}

TEST(VoronoiTest, UnreachableComponentBelongsToNoCell) {
  MeshData a = Square(), b = Square();
  const uint32_t offset = static_cast<uint32_t>(a.vertex_count());
  for (size_t i = 0; i < b.positions.size(); ++i) {
    a.positions.push_back(b.positions[i] + (i % 3 == 0 ? 2 : 0));
  }
  for (uint32_t v : b.faces) a.faces.push_back(v + offset);
  const Fixture fx = Solve(a, {GridVertex(10, 10), GridVertex(40, 45)});
  absl::StatusOr<VoronoiDiagram> vd = BuildVoronoi(fx.mesh, fx.field);
  ASSERT_TRUE(vd.ok()) << vd.status();
  CheckPartition(fx, *vd);
  CheckBoundaries(fx, *vd);
  EXPECT_NEAR(vd->total_area, 1.0, 1e-12);  // only the first square
  EXPECT_EQ(vd->cells.size(), 2u);

  DistanceField wrong = fx.field;
  wrong.internal_source.pop_back();
  EXPECT_EQ(BuildVoronoi(fx.mesh, wrong).status().code(), absl::StatusCode::kInvalidArgument);
}

// Cells by travel time at a constant speed with equal weights are the geodesic cells, whatever the
// speed: the boundary point on an edge is placed where the sites' times meet with the edge timed at
// that speed (it was placed with the edge in metres against times in seconds, so cells moved with
// the speed: 0.27% of their area at 36 km/h). Several weights of one value too.
TEST(VoronoiTest, CellsByTimeAtAConstantSpeedAreTheGeodesicCells) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 40;
  spec.width = spec.height = 400;  // metres, so that a second is not a metre at any speed here
  spec.alternate_diagonals = true;
  spec.jitter = 0.15;
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(MakeGrid(spec));
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  VoronoiQuery query;
  for (int k : {41 * 8 + 9, 41 * 30 + 12, 41 * 20 + 33}) {
    query.sites.push_back(SurfacePoint::AtVertex(static_cast<uint32_t>(k)));
  }
  absl::StatusOr<VoronoiDiagram> metres = ComputeVoronoi(*mesh, query);
  ASSERT_TRUE(metres.ok()) << metres.status();
  ASSERT_EQ(metres->cells.size(), 3u);
  for (double kmh : {3.6, 7.2, 36.0}) {
    for (double weight : {1.0, 2.5}) {
      VoronoiQuery timed = query;
      timed.options.travel = TravelCost{};
      timed.options.travel->speed_kmh = kmh;
      timed.options.travel->face_weight =
          std::make_shared<std::vector<double>>(mesh->face_count(), weight);
      absl::StatusOr<VoronoiDiagram> vd = ComputeVoronoi(*mesh, timed);
      ASSERT_TRUE(vd.ok()) << vd.status();
      ASSERT_EQ(vd->cells.size(), 3u);
      for (size_t c = 0; c < 3; ++c) {
        EXPECT_NEAR(vd->cells[c].area, metres->cells[c].area, 1e-9 * metres->cells[c].area)
            << "cell " << c << " at " << kmh << " km/h, weight " << weight;
      }
    }
  }
  // A travel-time field without its travel cost is refused, not read as metres.
  VoronoiQuery timed = query;
  timed.options.travel = TravelCost{};
  timed.options.travel->speed_kmh = 36;
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, query.sites, timed.options);
  ASSERT_TRUE(field.ok()) << field.status();
  EXPECT_EQ(BuildVoronoi(*mesh, *field).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace geodex
