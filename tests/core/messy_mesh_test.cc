// Messy input built in code: what TriangleMesh::Build reports, repairs and rejects, and that the
// solver stays finite where a source is reachable and exactly +inf where it is not. Also the
// per-vertex quantities Build derives (angle sums, saddle and boundary flags).
//
// Reachability follows the documented model (geodex/triangle_mesh.h): faces are joined across
// edges shared by exactly two faces; an edge of three or more faces is cut, and a vertex where
// several fans of faces meet only at that vertex is split so that paths never cross it. A source
// AT such a vertex seeds every copy.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"

namespace geodex {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kNoLabel = 0xffffffffu;

// Appends `b` to `a` (b's vertex ids shifted).
MeshData Concat(MeshData a, const MeshData& b) {
  const uint32_t offset = static_cast<uint32_t>(a.vertex_count());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (uint32_t v : b.faces) a.faces.push_back(v + offset);
  return a;
}

MeshData Translated(MeshData m, const Vec3& t) {
  ApplyRigidMotion(&m, {0, 0, 1}, 0, t);
  return m;
}

MeshData SmallGrid(int cells) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = cells;
  spec.width = spec.height = cells;
  spec.alternate_diagonals = true;
  return MakeGrid(spec);
}

// File vertices reachable from a vertex source under the documented model, computed here from
// the face list alone: union faces across edges with exactly two faces, take every component
// with a face at the source, and collect those faces' corners.
std::vector<bool> ReachableFrom(const MeshData& m, uint32_t source) {
  const size_t nf = m.face_count();
  std::vector<uint32_t> parent(nf);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.faces[3 * f + k], b = m.faces[3 * f + (k + 1) % 3];
      std::vector<uint32_t> sharing;
      for (size_t g = 0; g < nf; ++g) {
        const uint32_t* c = &m.faces[3 * g];
        const bool has_a = c[0] == a || c[1] == a || c[2] == a;
        const bool has_b = c[0] == b || c[1] == b || c[2] == b;
        if (has_a && has_b) sharing.push_back(static_cast<uint32_t>(g));
      }
      if (sharing.size() == 2) parent[find(sharing[0])] = find(sharing[1]);
    }
  }
  std::vector<bool> root_reached(nf, false);
  for (size_t f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      if (m.faces[3 * f + k] == source) root_reached[find(static_cast<uint32_t>(f))] = true;
    }
  }
  std::vector<bool> reachable(m.vertex_count(), false);
  for (size_t f = 0; f < nf; ++f) {
    if (!root_reached[find(static_cast<uint32_t>(f))]) continue;
    for (int k = 0; k < 3; ++k) reachable[m.faces[3 * f + k]] = true;
  }
  return reachable;
}

// No NaN anywhere; finite with a real label where reachable; exactly +inf and 0xffffffff where not.
void ExpectSaneField(const DistanceField& f, const std::vector<bool>& reachable) {
  ASSERT_EQ(f.distance.size(), reachable.size());
  ASSERT_EQ(f.source.size(), reachable.size());
  for (size_t v = 0; v < reachable.size(); ++v) {
    EXPECT_FALSE(std::isnan(f.distance[v])) << "vertex " << v;
    if (reachable[v]) {
      EXPECT_TRUE(std::isfinite(f.distance[v])) << "vertex " << v << ": " << f.distance[v];
      EXPECT_NE(f.source[v], kNoLabel) << "vertex " << v;
    } else {
      EXPECT_EQ(f.distance[v], kInf) << "vertex " << v;
      EXPECT_EQ(f.source[v], kNoLabel) << "vertex " << v;
    }
  }
  for (size_t v = 0; v < f.internal_distance.size(); ++v) {
    EXPECT_FALSE(std::isnan(f.internal_distance[v])) << "internal vertex " << v;
  }
}

// Where reachable, the distance must be Euclidean from `p` (all meshes here whose exact values
// are checked are planar convex pieces, or fans seen from their apex).
void ExpectEuclideanWhereReachable(const MeshData& m, const DistanceField& f, const Vec3& p,
                                   const std::vector<bool>& reachable) {
  for (uint32_t v = 0; v < m.vertex_count(); ++v) {
    if (!reachable[v]) continue;
    EXPECT_NEAR(f.distance[v], Distance3(p, VertexPosition(m, v)), 1e-12) << "vertex " << v;
  }
}

absl::StatusOr<TriangleMesh> Build(const MeshData& m, bool strict = false) {
  MeshBuildOptions options;
  options.strict = strict;
  return TriangleMesh::Build(m, options);
}

// ------------------------------------------------------------------------------------------------
// Meshes.

// Three triangles sharing the edge 0-1 (a "book" with three pages).
MeshData Book() {
  return Soup({{0, 0, 0}, {0, 0, 1}, {1, 0, 0.5}, {-0.5, 0.8, 0.5}, {-0.5, -0.8, 0.5}},
              {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
}

// Two planar fans meeting only at vertex 0 (a bowtie): fan A on x > 0, fan B on x < 0.
MeshData Bowtie() {
  const double c = std::cos(kPi / 3), s = std::sin(kPi / 3);
  return Soup({{0, 0, 0}, {c, -s, 0}, {1, 0, 0}, {c, s, 0}, {-c, s, 0}, {-1, 0, 0}, {-c, -s, 0}},
              {{0, 1, 2}, {0, 2, 3}, {0, 4, 5}, {0, 5, 6}});
}

// A 4 x 4 grid with face 9 wound the other way.
MeshData FlippedFaceGrid() {
  MeshData m = SmallGrid(4);
  std::swap(m.faces[3 * 9 + 1], m.faces[3 * 9 + 2]);
  return m;
}

// A flat square (diamond) a-d-b-c whose lower half is split at m, the midpoint of a-b, closed by
// the zero-area face (a, m, b) (a T-junction sealed by a sliver).
//        c
//      /   \          a = 0 (0,0)  b = 1 (2,0)  c = 2 (1,1)  d = 3 (1,-1)  m = 4 (1,0)
//     a--m--b
//      \ | /
//        d
MeshData SealedTJunction() {
  return Soup({{0, 0, 0}, {2, 0, 0}, {1, 1, 0}, {1, -1, 0}, {1, 0, 0}},
              {{0, 1, 2}, {0, 3, 4}, {4, 3, 1}, {0, 4, 1}});
}

// The unit square 0-1-2-3 plus vertex 4 at the same position as 2, joined by the face (1, 4, 2)
// whose two corners coincide.
MeshData CoincidentCorners() {
  return Soup({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, 1, 0}},
              {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}});
}

// ------------------------------------------------------------------------------------------------
// Components and isolated vertices.

TEST(MessyMeshTest, OtherComponentIsExactlyUnreachable) {
  const MeshData a = SmallGrid(4);
  const MeshData m = Concat(a, Translated(a, {10, 0, 0}));
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().components, 2u);
  EXPECT_EQ(mesh->report().isolated_vertices, 0u);
  EXPECT_EQ(mesh->report().boundary_loops, 2u);
  absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(6)});
  ASSERT_TRUE(f.ok()) << f.status();
  const std::vector<bool> reachable = ReachableFrom(m, 6);
  ASSERT_EQ(std::count(reachable.begin(), reachable.end(), true), 25);
  ExpectSaneField(*f, reachable);
  ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, 6), reachable);

  // One source per component: everything reachable, each labelled by its own component's source.
  f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(6), SurfacePoint::AtVertex(25 + 18)});
  ASSERT_TRUE(f.ok()) << f.status();
  ExpectSaneField(*f, std::vector<bool>(m.vertex_count(), true));
  for (uint32_t v = 0; v < m.vertex_count(); ++v) {
    const uint32_t own = v < 25 ? 6 : 25 + 18;
    EXPECT_EQ(f->source[v], v < 25 ? 0u : 1u) << v;
    EXPECT_NEAR(f->distance[v], Distance3(VertexPosition(m, own), VertexPosition(m, v)), 1e-12)
        << v;
  }
}

TEST(MessyMeshTest, IsolatedVerticesAreCountedAndUnreachable) {
  MeshData m = SmallGrid(3);  // 16 vertices
  // One far away, one at the very position of grid vertex 5.
  const Vec3 at5 = VertexPosition(m, 5);
  m.positions.insert(m.positions.end(), {7, 7, 7});
  m.positions.insert(m.positions.end(), at5.begin(), at5.end());
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().isolated_vertices, 2u);
  EXPECT_EQ(mesh->report().components, 1u);
  EXPECT_TRUE(mesh->IsIsolated(16));
  EXPECT_TRUE(mesh->IsIsolated(17));
  EXPECT_FALSE(mesh->IsIsolated(5));
  absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(f.ok()) << f.status();
  std::vector<bool> reachable(18, true);
  reachable[16] = reachable[17] = false;
  ExpectSaneField(*f, reachable);
  ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, 0), reachable);
}

// ------------------------------------------------------------------------------------------------
// Non-manifold input.

TEST(MessyMeshTest, NonManifoldEdgeIsCutAndReported) {
  const MeshData m = Book();
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().non_manifold_edges, 1u);
  // With the edge cut, each page meets the others only at 0 and at 1: both are split.
  EXPECT_EQ(mesh->report().non_manifold_vertices, 2u);
  // Cut at the spine, the three pages are separate pieces; through shared vertices, one.
  EXPECT_EQ(mesh->report().components, 3u);
  EXPECT_EQ(mesh->report().vertex_connected_components, 1u);
  EXPECT_EQ(mesh->report().degenerate_faces, 0u);

  // From a page's tip: its own page only.
  absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(2)});
  ASSERT_TRUE(f.ok()) << f.status();
  std::vector<bool> reachable = ReachableFrom(m, 2);
  ASSERT_EQ(reachable, (std::vector<bool>{true, true, true, false, false}));
  ExpectSaneField(*f, reachable);
  ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, 2), reachable);

  // From a spine vertex: every page (each page is a single triangle: Euclidean).
  f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(f.ok()) << f.status();
  reachable.assign(5, true);
  ExpectSaneField(*f, reachable);
  ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, 0), reachable);
}

TEST(MessyMeshTest, BowtieVertexIsSplitAndNotCrossed) {
  const MeshData m = Bowtie();
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().non_manifold_vertices, 1u);
  EXPECT_EQ(mesh->report().non_manifold_edges, 0u);
  EXPECT_EQ(mesh->report().components, 2u);  // the two fans, once cut at the shared vertex
  EXPECT_EQ(mesh->report().vertex_connected_components, 1u);
  EXPECT_EQ(mesh->vertex_count(), 8u);  // vertex 0 has a second internal copy
  EXPECT_EQ(mesh->FileVertex(7), 0u);

  absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(2)});
  ASSERT_TRUE(f.ok()) << f.status();
  std::vector<bool> reachable = ReachableFrom(m, 2);
  ASSERT_EQ(reachable, (std::vector<bool>{true, true, true, true, false, false, false}));
  ExpectSaneField(*f, reachable);
  ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, 2), reachable);

  // From the junction itself both fans are reached (fan B's far side is 1 away).
  f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(f.ok()) << f.status();
  reachable.assign(7, true);
  ExpectSaneField(*f, reachable);
  ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, 0), reachable);
}

// ------------------------------------------------------------------------------------------------
// Orientation and degenerate faces.

TEST(MessyMeshTest, InconsistentlyOrientedFaceIsFlippedAndDistancesStayExact) {
  const MeshData m = FlippedFaceGrid();
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().flipped_faces, 1u);
  EXPECT_EQ(mesh->report().orientation_cuts, 0u);
  EXPECT_TRUE(mesh->FaceFlipped(9));
  EXPECT_FALSE(mesh->FaceFlipped(8));
  EXPECT_EQ(mesh->report().non_manifold_edges, 0u);
  EXPECT_EQ(mesh->report().non_manifold_vertices, 0u);
  for (uint32_t s : {0u, 12u, 24u}) {
    absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    const std::vector<bool> all(m.vertex_count(), true);
    ExpectSaneField(*f, all);
    ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, s), all);
  }
  // A face point in the flipped face, named in the FILE's corner order.
  const uint32_t* c = &m.faces[3 * 9];
  Vec3 p{};
  const double w[3] = {0.6, 0.3, 0.1};
  for (int k = 0; k < 3; ++k) {
    for (int x = 0; x < 3; ++x) p[x] += w[k] * VertexPosition(m, c[k])[x];
  }
  absl::StatusOr<DistanceField> f =
      ComputeDistanceField(*mesh, {SurfacePoint::InFace(9, w[0], w[1], w[2])});
  ASSERT_TRUE(f.ok()) << f.status();
  ExpectEuclideanWhereReachable(m, *f, p, std::vector<bool>(m.vertex_count(), true));
}

TEST(MessyMeshTest, ZeroAreaFaceIsReportedAndSolvesStayFinite) {
  const MeshData m = SealedTJunction();
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().degenerate_faces, 1u);
  EXPECT_TRUE(mesh->FaceDegenerate(3));
  EXPECT_FALSE(mesh->FaceDegenerate(0));
  EXPECT_EQ(mesh->report().non_manifold_edges, 0u);
  EXPECT_EQ(mesh->report().flipped_faces, 0u);
  EXPECT_TRUE(mesh->IsPseudoSourceCandidate(4));  // touches the degenerate face
  for (uint32_t s = 0; s < 5; ++s) {
    absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    ExpectSaneField(*f, std::vector<bool>(5, true));
  }
}

// The sealed T-junction is a flat convex diamond: every distance is Euclidean. From c, the
// shortest path to d runs straight through m, across the zero-area face's vertex.
TEST(MessyMeshTest, ZeroAreaFaceKeepsFlatDistancesExact) {
  const MeshData m = SealedTJunction();
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  for (uint32_t s = 0; s < 5; ++s) {
    absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    SCOPED_TRACE("source " + std::to_string(s));
    ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, s), std::vector<bool>(5, true));
  }
}

TEST(MessyMeshTest, CoincidentCornersGiveEqualDistancesAtBothCopies) {
  const MeshData m = CoincidentCorners();
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().degenerate_faces, 1u);
  EXPECT_TRUE(mesh->FaceDegenerate(2));
  for (uint32_t s = 0; s < 5; ++s) {
    absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(f.ok()) << f.status();
    SCOPED_TRACE("source " + std::to_string(s));
    ExpectSaneField(*f, std::vector<bool>(5, true));
    // Vertices 2 and 4 are one point of the surface (joined by a zero-length edge).
    ExpectEuclideanWhereReachable(m, *f, VertexPosition(m, s), std::vector<bool>(5, true));
  }
}

// ------------------------------------------------------------------------------------------------
// Build errors and strict mode.

void ExpectInvalid(const absl::StatusOr<TriangleMesh>& mesh, absl::string_view naming) {
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument) << mesh.status();
  EXPECT_NE(mesh.status().message().find(naming), absl::string_view::npos)
      << "message should name \"" << naming << "\": " << mesh.status();
}

TEST(MessyMeshTest, BuildRejectsNonFiniteCoordinatesNamingTheVertex) {
  MeshData m = SmallGrid(2);
  m.positions[3 * 4 + 1] = std::numeric_limits<double>::quiet_NaN();
  ExpectInvalid(Build(m), "vertex 4");
  m = SmallGrid(2);
  m.positions[3 * 7 + 2] = kInf;
  ExpectInvalid(Build(m), "vertex 7");
}

TEST(MessyMeshTest, BuildRejectsOutOfRangeIndexNamingTheFace) {
  MeshData m = SmallGrid(2);  // 9 vertices, 8 faces
  m.faces[3 * 5 + 2] = 9;
  ExpectInvalid(Build(m), "face 5");
}

TEST(MessyMeshTest, BuildRejectsRepeatedVertexNamingTheFace) {
  MeshData m = SmallGrid(2);
  m.faces[3 * 6 + 1] = m.faces[3 * 6];
  ExpectInvalid(Build(m), "face 6");
}

TEST(MessyMeshTest, BuildRejectsEmptyMeshes) {
  absl::StatusOr<TriangleMesh> mesh = Build(MeshData{});
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument) << mesh.status();
  MeshData no_faces = SmallGrid(2);
  no_faces.faces.clear();
  mesh = Build(no_faces);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument) << mesh.status();
}

TEST(MessyMeshTest, StrictModeRejectsNonManifoldAndMisorientedInput) {
  for (const auto& [name, m] :
       std::vector<std::pair<std::string, MeshData>>{{"non-manifold edge", Book()},
                                                     {"bowtie vertex", Bowtie()},
                                                     {"flipped face", FlippedFaceGrid()}}) {
    absl::StatusOr<TriangleMesh> mesh = Build(m, /*strict=*/true);
    ASSERT_FALSE(mesh.ok()) << name;
    EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument)
        << name << ": " << mesh.status();
    EXPECT_TRUE(Build(m, /*strict=*/false).ok()) << name;
  }
  EXPECT_TRUE(Build(SmallGrid(3), /*strict=*/true).ok());
  EXPECT_TRUE(Build(MakeCube(2, 1.0), /*strict=*/true).ok());
}

// ------------------------------------------------------------------------------------------------
// Derived per-vertex quantities.

TEST(MeshQuantitiesTest, CubeCornerAngleSumIsThreeHalvesPi) {
  const MeshData m = MakeCube(2, 1.0);  // 26 vertices: 8 corners, 12 edge midpoints, 6 centres
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  int corners = 0;
  for (uint32_t v = 0; v < m.vertex_count(); ++v) {
    const Vec3 p = VertexPosition(m, v);
    const bool corner =
        (p[0] == 0 || p[0] == 1) && (p[1] == 0 || p[1] == 1) && (p[2] == 0 || p[2] == 1);
    corners += corner;
    EXPECT_NEAR(mesh->AngleSum(v), corner ? 1.5 * kPi : 2 * kPi, 1e-12) << v;
    EXPECT_EQ(mesh->IsSaddle(v), !corner) << v;  // flat ones count as saddles by design
    EXPECT_FALSE(mesh->IsBoundary(v)) << v;
  }
  EXPECT_EQ(corners, 8);
  EXPECT_EQ(mesh->report().saddle_vertices, 18u);
  EXPECT_EQ(mesh->report().boundary_vertices, 0u);
  EXPECT_EQ(mesh->report().boundary_edges, 0u);
  EXPECT_EQ(mesh->report().boundary_loops, 0u);
  EXPECT_EQ(mesh->report().components, 1u);
}

TEST(MeshQuantitiesTest, FlatInteriorVertexSumsToTwoPiAndCountsAsSaddle) {
  GridSpec spec;
  spec.cells_x = 5;
  spec.cells_y = 4;
  spec.jitter = 0.2;
  spec.alternate_diagonals = true;
  const MeshData m = MakeGrid(spec);
  absl::StatusOr<TriangleMesh> mesh = Build(m);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  int interior = 0, boundary = 0;
  for (int j = 0; j <= 4; ++j) {
    for (int i = 0; i <= 5; ++i) {
      const uint32_t v = j * 6 + i;
      const bool on_boundary = i == 0 || j == 0 || i == 5 || j == 4;
      EXPECT_EQ(mesh->IsBoundary(v), on_boundary) << v;
      if (on_boundary) {
        ++boundary;
        EXPECT_TRUE(mesh->IsPseudoSourceCandidate(v)) << v;
      } else {
        ++interior;
        EXPECT_NEAR(mesh->AngleSum(v), 2 * kPi, 1e-12) << v;
        EXPECT_TRUE(mesh->IsSaddle(v)) << v;
        EXPECT_TRUE(mesh->IsPseudoSourceCandidate(v)) << v;
      }
    }
  }
  EXPECT_EQ(mesh->report().saddle_vertices, static_cast<uint64_t>(interior));
  EXPECT_EQ(mesh->report().boundary_vertices, static_cast<uint64_t>(boundary));
  EXPECT_EQ(mesh->report().boundary_loops, 1u);
  EXPECT_EQ(mesh->report().boundary_edges, 18u);
}

// A monkey saddle's centre: 8 neighbours on the unit circle, alternately up and down by h. Each
// of the 8 corner angles is the angle between two unit-circle neighbours' vectors.
TEST(MeshQuantitiesTest, MonkeySaddleVertexHasExcessAngleAndIsSaddle) {
  const double h = 0.6;
  std::vector<Vec3> points = {{0, 0, 0}};
  std::vector<std::array<uint32_t, 3>> faces;
  for (int k = 0; k < 8; ++k) {
    const double theta = 2 * kPi * k / 8;
    points.push_back({std::cos(theta), std::sin(theta), k % 2 ? -h : h});
    faces.push_back({0, static_cast<uint32_t>(1 + k), static_cast<uint32_t>(1 + (k + 1) % 8)});
  }
  absl::StatusOr<TriangleMesh> mesh = Build(Soup(points, faces));
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const double corner = std::acos((std::cos(kPi / 4) - h * h) / (1 + h * h));
  EXPECT_NEAR(mesh->AngleSum(0), 8 * corner, 1e-12);
  EXPECT_GT(mesh->AngleSum(0), 2 * kPi + 0.5);
  EXPECT_TRUE(mesh->IsSaddle(0));
  EXPECT_FALSE(mesh->IsBoundary(0));
  for (uint32_t v = 1; v <= 8; ++v) {
    EXPECT_TRUE(mesh->IsBoundary(v)) << v;
    EXPECT_FALSE(mesh->IsSaddle(v)) << v;
  }
  EXPECT_EQ(mesh->report().saddle_vertices, 1u);
  EXPECT_EQ(mesh->report().boundary_vertices, 8u);
}

TEST(MeshQuantitiesTest, ConvexConeApexIsNotSaddleAndWavyApexIs) {
  const Cone convex = MakeCone(10, 3, 1.0, 0.7, /*saddle=*/false);
  absl::StatusOr<TriangleMesh> mesh = Build(convex.data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_NEAR(mesh->AngleSum(0), convex.total_angle, 1e-12);
  EXPECT_LT(mesh->AngleSum(0), 2 * kPi - 0.1);
  EXPECT_FALSE(mesh->IsSaddle(0));
  EXPECT_FALSE(mesh->IsPseudoSourceCandidate(0));

  const Cone wavy = MakeCone(10, 3, 1.0, 0.7, /*saddle=*/true);
  mesh = Build(wavy.data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_NEAR(mesh->AngleSum(0), wavy.total_angle, 1e-12);
  EXPECT_TRUE(mesh->IsSaddle(0));
  EXPECT_EQ(mesh->report().boundary_loops, 1u);

  const Cylinder cylinder = MakeOpenCylinder(8, 3, 1.0, 1.0);
  mesh = Build(cylinder.data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().boundary_loops, 2u);
  EXPECT_EQ(mesh->report().boundary_vertices, 16u);
}

}  // namespace
}  // namespace geodex
