// Path backtracing: the polyline's length equals the field's distance, it is straight across every
// edge it crosses (unfolds to a line), and it bends only at saddle or boundary vertices.

#include "geodex/shortest_path.h"

#include <cmath>
#include <string>

#include "geodex/geodesic_solver.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

double Norm(const std::array<double, 3>& a) {
  return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}
std::array<double, 3> Sub(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double Dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void CheckPath(const MeshData& data, const TriangleMesh& mesh, const DistanceField& field,
               uint32_t v) {
  absl::StatusOr<GeodesicPath> path = TracePathFromVertex(mesh, field, v);
  ASSERT_TRUE(path.ok()) << "vertex " << v << ": " << path.status();
  ASSERT_GE(path->points.size(), 1u);
  EXPECT_NEAR(path->length, field.distance[v], 1e-12 * std::max(1.0, field.distance[v]))
      << "vertex " << v;
  EXPECT_EQ(path->source, field.source[v]);
  const auto& pts = path->points;
  ASSERT_EQ(pts.front().where.kind, SurfacePoint::Kind::kVertex);
  EXPECT_EQ(pts.front().where.vertex, v);
  for (size_t i = 0; i < pts.size(); ++i) {
    const SurfacePoint& w = pts[i].where;
    if (w.kind == SurfacePoint::Kind::kVertex) {
      // Interior bends happen only where paths may bend.
      if (i > 0 && i + 1 < pts.size()) {
        EXPECT_TRUE(mesh.IsPseudoSourceCandidate(w.vertex)) << "bend at convex vertex " << w.vertex;
      }
      const Vec3 p = VertexPosition(data, w.vertex);
      EXPECT_LT(Norm(Sub(pts[i].position, {p[0], p[1], p[2]})), 1e-12);
    } else if (w.kind == SurfacePoint::Kind::kEdge && i > 0 && i + 1 < pts.size()) {
      // The point lies on its edge, and the two segments make supplementary angles with the
      // edge: the path unfolds to a straight line across it.
      const Vec3 a = VertexPosition(data, w.edge_from), b = VertexPosition(data, w.edge_to);
      const std::array<double, 3> e = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double el = Norm(e);
      std::array<double, 3> on_edge;
      for (int k = 0; k < 3; ++k) on_edge[k] = a[k] + w.t * e[k];
      EXPECT_LT(Norm(Sub(pts[i].position, on_edge)), 1e-12 * (1 + el));
      const auto back = Sub(pts[i - 1].position, pts[i].position);
      const auto ahead = Sub(pts[i + 1].position, pts[i].position);
      if (Norm(back) > 1e-9 * el && Norm(ahead) > 1e-9 * el) {
        const double c1 = Dot(back, e) / (Norm(back) * el), c2 = Dot(ahead, e) / (Norm(ahead) * el);
        EXPECT_NEAR(c1 + c2, 0, 1e-7)
            << "path bends on edge " << w.edge_from << "-" << w.edge_to << " (vertex " << v << ")";
      }
    }
  }
}

class PathTest : public ::testing::TestWithParam<std::string> {};

TEST_P(PathTest, PathLengthEqualsDistanceAndPathIsStraightAcrossEdges) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok());
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok());
  const uint32_t n = mesh->file_vertex_count();
  absl::StatusOr<DistanceField> field =
      ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(n / 2)});
  ASSERT_TRUE(field.ok());
  for (uint32_t v = 0; v < n; v += std::max(1u, n / 150)) CheckPath(*data, *mesh, *field, v);
}

TEST_P(PathTest, PathsFromFaceAndEdgeSourcesEndOnTheSource) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok());
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok());
  const SurfacePoint src = SurfacePoint::InFace(7, 0.2, 0.3, 0.5);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {src});
  ASSERT_TRUE(field.ok());
  const uint32_t n = mesh->file_vertex_count();
  for (uint32_t v = 0; v < n; v += std::max(1u, n / 60)) {
    CheckPath(*data, *mesh, *field, v);
    absl::StatusOr<GeodesicPath> path = TracePathFromVertex(*mesh, *field, v);
    ASSERT_TRUE(path.ok());
    const SurfacePoint& end = path->points.back().where;
    if (field->distance[v] > 0 && path->points.size() > 1) {
      // Ends at the face point itself (or at one of its face's corners when reached straight).
      ASSERT_EQ(end.kind, SurfacePoint::Kind::kFace) << "vertex " << v;
      EXPECT_EQ(end.face, 7u);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(end.bary[k], src.bary[k], 1e-9);
    }
  }
}

// The direction field (issue 18): at every vertex the unit vector of the first step of the path
// TracePathFromVertex returns, for vertex, face-point and two-source fields; zero at sources.
TEST_P(PathTest, DirectionFieldIsTheFirstStepOfEveryPath) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok());
  const uint32_t n = mesh->file_vertex_count();
  for (const std::vector<SurfacePoint>& sources :
       {std::vector<SurfacePoint>{SurfacePoint::AtVertex(0)},
        std::vector<SurfacePoint>{SurfacePoint::InFace(7, 0.2, 0.3, 0.5),
                                  SurfacePoint::AtVertex(n / 2)}}) {
    absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sources);
    ASSERT_TRUE(field.ok());
    const std::vector<std::array<double, 3>> dir = ComputeDirectionField(*mesh, *field);
    ASSERT_EQ(dir.size(), n);
    int checked = 0;
    for (uint32_t v = 0; v < n; ++v) {
      absl::StatusOr<GeodesicPath> path = TracePathFromVertex(*mesh, *field, v);
      ASSERT_TRUE(path.ok()) << path.status();
      const auto& p = path->points;
      // The first point of the path away from v (an edge crossing may repeat v's position).
      size_t k = 1;
      const double scale = 1e-9 * (1 + field->distance[v]);
      while (k < p.size() &&
             std::hypot(p[k].position[0] - p[0].position[0], p[k].position[1] - p[0].position[1],
                        p[k].position[2] - p[0].position[2]) <= scale) {
        ++k;
      }
      if (k == p.size()) {  // v is a source
        EXPECT_EQ(dir[v], (std::array<double, 3>{0, 0, 0})) << v;
        continue;
      }
      std::array<double, 3> step;
      for (int c = 0; c < 3; ++c) step[c] = p[k].position[c] - p[0].position[c];
      const double len = std::hypot(step[0], step[1], step[2]);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(dir[v][c], step[c] / len, 1e-7) << "vertex " << v;
      ++checked;
    }
    EXPECT_GT(checked, 50);
  }
}

INSTANTIATE_TEST_SUITE_P(Meshes, PathTest,
                         ::testing::Values("knight.off", "three-peaks.off", "kitten.off",
                                           "bump-domain.off"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n) {
                             if (c == '.' || c == '-') c = '_';
                           }
                           return n;
                         });

TEST(PathTest, SaddleConePathBendsAtTheApex) {
  const int segments = 24, rings = 6;
  const Cone cone = MakeCone(segments, rings, 1.0, 0.5, /*saddle=*/true);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(cone.data);
  ASSERT_TRUE(mesh.ok());
  const uint32_t apex = 0;
  ASSERT_GT(cone.total_angle, 2 * M_PI + 0.1);
  // From a rim vertex to the opposite rim vertex the shortest path goes through the apex.
  const uint32_t a = 1 + (rings - 1) * segments, b = a + segments / 2;
  ASSERT_NEAR(ConeDistance(cone, a, b), 2.0, 1e-12);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(a)});
  ASSERT_TRUE(field.ok());
  absl::StatusOr<GeodesicPath> path = TracePathFromVertex(*mesh, *field, b);
  ASSERT_TRUE(path.ok()) << path.status();
  bool through_apex = false;
  for (const PathPoint& p : path->points) {
    through_apex |= p.where.kind == SurfacePoint::Kind::kVertex && p.where.vertex == apex;
  }
  EXPECT_TRUE(through_apex);
  EXPECT_NEAR(path->length, field->distance[b], 1e-12);
}

// On a plane the direction towards a vertex source is exactly the straight line to it; an
// unreferenced vertex has none (NaN).
TEST(PathTest, DirectionFieldOnAPlanePointsAtTheSource) {
  GridSpec spec;
  MeshData data = MakeGrid(spec);
  const uint32_t n = static_cast<uint32_t>(data.vertex_count());
  data.positions.insert(data.positions.end(), {5, 5, 5});
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok());
  const uint32_t source = n / 2 + 3;
  absl::StatusOr<DistanceField> field =
      ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(source)});
  ASSERT_TRUE(field.ok());
  const std::vector<std::array<double, 3>> dir = ComputeDirectionField(*mesh, *field);
  const Vec3 s = VertexPosition(data, source);
  for (uint32_t v = 0; v < n; ++v) {
    if (v == source) {
      EXPECT_EQ(dir[v], (std::array<double, 3>{0, 0, 0}));
      continue;
    }
    const Vec3 p = VertexPosition(data, v);
    const double len = Distance3(s, p);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(dir[v][c], (s[c] - p[c]) / len, 1e-12) << v;
  }
  EXPECT_TRUE(std::isnan(dir[n][0]) && std::isnan(dir[n][1]) && std::isnan(dir[n][2]));
}

// The rare case a solve seldom produces: a vertex reached from a window on an edge it ends, with
// the window's image below that edge, so its first step runs into the neighbouring face (here
// folded out of the plane). A hand-made origin, against the unfolding done by hand.
TEST(PathTest, DirectionFieldStepsIntoTheFaceAcrossTheEdge) {
  MeshData data;
  data.positions = {0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0.5};  // A B C D
  data.faces = {0, 1, 2, 1, 0, 3};                               // ABC, BAD (fold along AB)
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok());
  ASSERT_EQ(mesh->From(0), 0u);  // half-edge 0 runs A -> B in face ABC
  ASSERT_EQ(mesh->To(0), 1u);
  DistanceField field;
  field.internal_distance.assign(4, 1.0);
  field.internal_origin.assign(4, VertexOrigin{});
  field.internal_origin[0] = VertexOrigin{0, kNoIndex, 0.5, -0.8};  // image below AB, from A
  const std::vector<std::array<double, 3>> dir = ComputeDirectionField(*mesh, field);
  // In face BAD the point 0.8 below AB: A + 0.5 * (1, 0, 0) + 0.8 * n, n the unit vector in BAD
  // perpendicular to AB towards D.
  const double n[3] = {0, -1 / std::sqrt(1.25), 0.5 / std::sqrt(1.25)};
  double want[3] = {0.5, 0.8 * n[1], 0.8 * n[2]};
  const double len = std::sqrt(want[0] * want[0] + want[1] * want[1] + want[2] * want[2]);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(dir[0][c], want[c] / len, 1e-12) << c;
  // From C (the opposite corner) towards the same image: inside ABC, through AB.
  field.internal_origin[2] = VertexOrigin{0, kNoIndex, 0.5, -0.8};
  const std::vector<std::array<double, 3>> from_c = ComputeDirectionField(*mesh, field);
  EXPECT_NEAR(from_c[2][0], 0, 1e-12);
  EXPECT_NEAR(from_c[2][1], -1, 1e-12);
  EXPECT_NEAR(from_c[2][2], 0, 1e-12);
}

TEST(PathTest, UnreachableAndUnknownVerticesAreErrors) {
  GridSpec spec;
  MeshData a = MakeGrid(spec);
  const uint32_t n = static_cast<uint32_t>(a.vertex_count());
  a.positions.insert(a.positions.end(), {5, 5, 5});  // an unreferenced vertex
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(a);
  ASSERT_TRUE(mesh.ok());
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(field.ok());
  EXPECT_EQ(TracePathFromVertex(*mesh, *field, n).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(TracePathFromVertex(*mesh, *field, n + 1).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// An unreachable target's error says why: another part of the surface, a vertex no face uses, or
// beyond max_distance.
TEST(UnreachableReasonTest, SaysWhy) {
  // Two triangles apart (0-1-2 and 3-4-5) and vertex 6 that no face uses.
  MeshData data;
  data.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 0, 0, 6, 0, 0, 5, 1, 0, 9, 9, 9};
  data.faces = {0, 1, 2, 3, 4, 5};
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  PathQueryOptions options;
  absl::StatusOr<PathQueryResult> apart =
      ComputeShortestPath(*mesh, SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(4), options);
  EXPECT_EQ(apart.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(apart.status().message().find("it is on another part of the surface"),
            std::string::npos)
      << apart.status();
  EXPECT_NE(apart.status().message().find("the mesh has 2 parts"), std::string::npos)
      << apart.status();
  EXPECT_EQ(
      UnreachableReason(*mesh, SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(6), kUnreachable),
      "it is a vertex no face uses");
  options.solver.max_distance = 0.5;
  absl::StatusOr<PathQueryResult> far =
      ComputeShortestPath(*mesh, SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(1), options);
  EXPECT_EQ(far.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(far.status().message().find("farther than the max_distance limit (0.5)"),
            std::string::npos)
      << far.status();
  EXPECT_EQ(UnreachableReason(*mesh, SurfacePoint::OnEdge(0, 1, 0.5),
                              SurfacePoint::InFace(1, 0.2, 0.3, 0.5), kUnreachable)
                .rfind("it is on another part", 0),
            0u);
}

}  // namespace
}  // namespace geodex
