// ICH against CGAL's Surface_mesh_shortest_path on every committed mesh, and self-checks of the
// CGAL reference itself (testkit/cgal_reference.h).

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "testkit/cgal_reference.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kRelTol = 1e-10;  // times the largest finite distance

double Ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

// An edge that only one face has (an edge of the boundary), or {0, 0} if the mesh is closed.
std::pair<uint32_t, uint32_t> SomeBoundaryEdge(const MeshData& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> count;
  for (size_t f = 0; f < m.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.faces[3 * f + k], b = m.faces[3 * f + (k + 1) % 3];
      ++count[{std::min(a, b), std::max(a, b)}];
    }
  }
  for (size_t f = 0; f < m.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.faces[3 * f + k], b = m.faces[3 * f + (k + 1) % 3];
      if (count[{std::min(a, b), std::max(a, b)}] == 1) return {a, b};
    }
  }
  return {0, 0};
}

struct SourceSet {
  std::string name;
  std::vector<SurfacePoint> sources;
};

std::vector<SourceSet> SourceSetsFor(const MeshData& m) {
  const uint32_t v = static_cast<uint32_t>(m.vertex_count());
  const uint32_t f = static_cast<uint32_t>(m.face_count() / 3);
  std::vector<SourceSet> sets = {
      {"vertex 0", {SurfacePoint::AtVertex(0)}},
      {"vertex V/2", {SurfacePoint::AtVertex(v / 2)}},
      {"vertices 0 + V/2", {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(v / 2)}},
      {"edge point", {SurfacePoint::OnEdge(m.faces[3 * f + 1], m.faces[3 * f + 2], 0.37)}},
      {"face point", {SurfacePoint::InFace(2 * f, 0.2, 0.3, 0.5)}},
  };
  const auto [a, b] = SomeBoundaryEdge(m);
  if (a != b) sets.push_back({"boundary edge point", {SurfacePoint::OnEdge(a, b, 0.61)}});
  return sets;
}

class IchVsCgalTest : public ::testing::TestWithParam<std::string> {};

TEST_P(IchVsCgalTest, DistancesMatchCgalAtEveryVertex) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok()) << data.status();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  double mesh_worst_abs = 0, mesh_worst_rel = 0;
  for (const SourceSet& set : SourceSetsFor(*data)) {
    SCOPED_TRACE(GetParam() + ", " + set.name);
    auto start = std::chrono::steady_clock::now();
    absl::StatusOr<DistanceField> ours = ComputeDistanceField(*mesh, set.sources);
    const double ours_ms = Ms(start);
    ASSERT_TRUE(ours.ok()) << ours.status();
    start = std::chrono::steady_clock::now();
    const std::vector<double> cgal = CgalDistances(*data, set.sources);
    const double cgal_ms = Ms(start);
    ASSERT_EQ(cgal.size(), data->vertex_count()) << "CGAL reference failed";
    ASSERT_EQ(ours->distance.size(), cgal.size());

    double max_d = 0;
    for (double d : cgal) {
      if (std::isfinite(d)) max_d = std::max(max_d, d);
    }
    const double tol = kRelTol * max_d;
    double max_abs = 0;
    uint32_t worst = 0;
    int failures = 0;
    for (uint32_t v = 0; v < cgal.size(); ++v) {
      const double ours_d = ours->distance[v];
      const double err = std::abs(ours_d - cgal[v]);
      const bool ok = (std::isinf(cgal[v]) && ours_d == kInf) || err <= tol;
      if (!ok && ++failures <= 8) {
        ADD_FAILURE() << "vertex " << v << ": ours " << ours_d << ", CGAL " << cgal[v] << " (error "
                      << err << ", tolerance " << tol << ")";
      }
      if (std::isfinite(err) && err > max_abs) {
        max_abs = err;
        worst = v;
      }
    }
    EXPECT_EQ(failures, 0) << failures << " vertices off";
    mesh_worst_abs = std::max(mesh_worst_abs, max_abs);
    mesh_worst_rel = std::max(mesh_worst_rel, max_abs / max_d);
    std::printf(
        "[ vs CGAL ] %-16s %-20s V=%5zu max|ours-cgal| = %.3e rel %.3e (vertex %u)  "
        "ours %.1f ms, CGAL %.1f ms\n",
        GetParam().c_str(), set.name.c_str(), cgal.size(), max_abs, max_abs / max_d, worst, ours_ms,
        cgal_ms);
  }
  std::printf("[ vs CGAL ] %-16s worst over all source sets: abs %.3e rel %.3e\n",
              GetParam().c_str(), mesh_worst_abs, mesh_worst_rel);
}

// A robot's local plan: waypoints at vertices close together, so each row's targeted solve steers
// towards a small ball around its targets and fits it again as the near ones become final. Every
// entry against CGAL's distance from the row's source.
TEST_P(IchVsCgalTest, LocalMatrixEntriesMatchCgal) {
  absl::StatusOr<MeshData> data = LoadTestMeshData(GetParam());
  ASSERT_TRUE(data.ok()) << data.status();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  // 9 waypoints among the vertices nearest (in 3D) to vertex V/3: every 1/9 of the nearest V/10.
  const uint32_t centre = static_cast<uint32_t>(data->vertex_count() / 3);
  auto at = [&](uint32_t v) {
    return std::array<double, 3>{data->positions[3 * v], data->positions[3 * v + 1],
                                 data->positions[3 * v + 2]};
  };
  std::vector<std::pair<double, uint32_t>> by_distance;
  for (uint32_t v = 0; v < data->vertex_count(); ++v) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (at(v)[k] - at(centre)[k]) * (at(v)[k] - at(centre)[k]);
    by_distance.push_back({d2, v});
  }
  std::sort(by_distance.begin(), by_distance.end());
  const size_t step = std::max<size_t>(1, data->vertex_count() / 90);
  std::vector<SurfacePoint> points;
  for (size_t i = 0; i < 9; ++i)
    points.push_back(SurfacePoint::AtVertex(by_distance[i * step].second));
  // Symmetric (each pair solved by one row) and not (every row solves every target).
  const std::vector<SurfacePoint> sources(points.begin(), points.begin() + 4);
  std::map<uint32_t, std::vector<double>> cgal_from;  // by source vertex
  for (const SurfacePoint& p : points) cgal_from[p.vertex] = CgalDistances(*data, {p});
  using Points = const std::vector<SurfacePoint>*;
  for (const auto& [rows, cols] : {std::pair<Points, Points>{&points, &points},
                                   std::pair<Points, Points>{&sources, &points}}) {
    absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(*mesh, *rows, *cols);
    ASSERT_TRUE(m.ok()) << m.status();
    for (size_t i = 0; i < rows->size(); ++i) {
      const std::vector<double>& cgal = cgal_from[(*rows)[i].vertex];
      ASSERT_EQ(cgal.size(), data->vertex_count()) << "CGAL reference failed";
      double max_d = 0;
      for (double d : cgal) {
        if (std::isfinite(d)) max_d = std::max(max_d, d);
      }
      for (size_t j = 0; j < cols->size(); ++j) {
        const double expected = cgal[(*cols)[j].vertex];
        EXPECT_NEAR(m->values[i * m->cols + j], expected, kRelTol * max_d)
            << "row " << i << " column " << j;
      }
    }
  }
}

std::string MeshTestName(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(CommittedMeshes, IchVsCgalTest, ::testing::ValuesIn(CommittedMeshNames()),
                         MeshTestName);

// ------------------------------------------------------------------------------------------------
// The reference itself.

// bump-domain is flat (z = 0) and convex: geodesic = Euclidean, for every kind of source.
TEST(CgalReferenceTest, FlatConvexDomainGivesEuclideanDistances) {
  absl::StatusOr<MeshData> data = LoadTestMeshData("bump-domain.off");
  ASSERT_TRUE(data.ok()) << data.status();
  const MeshData& m = *data;
  const uint32_t f = 1234;
  const uint32_t* c = &m.faces[3 * f];
  const Vec3 a = VertexPosition(m, c[0]), b = VertexPosition(m, c[1]), d = VertexPosition(m, c[2]);
  std::vector<std::pair<std::vector<SurfacePoint>, Vec3>> cases = {
      {{SurfacePoint::AtVertex(0)}, VertexPosition(m, 0)},
      {{SurfacePoint::AtVertex(2086)}, VertexPosition(m, 2086)},
      // Edge point a + 0.3 (b - a), named from b: t = 0.7.
      {{SurfacePoint::OnEdge(c[1], c[0], 0.7)},
       {0.7 * a[0] + 0.3 * b[0], 0.7 * a[1] + 0.3 * b[1], 0.7 * a[2] + 0.3 * b[2]}},
      {{SurfacePoint::InFace(f, 0.5, 0.3, 0.2)},
       {0.5 * a[0] + 0.3 * b[0] + 0.2 * d[0], 0.5 * a[1] + 0.3 * b[1] + 0.2 * d[1], 0}},
  };
  for (const auto& [sources, p] : cases) {
    const std::vector<double> cgal = CgalDistances(m, sources);
    ASSERT_EQ(cgal.size(), m.vertex_count());
    double worst = 0;
    for (uint32_t v = 0; v < m.vertex_count(); ++v) {
      const double exact = Distance3(p, VertexPosition(m, v));
      EXPECT_NEAR(cgal[v], exact, 1e-12 * 2) << SurfacePointToString(sources[0]) << " v " << v;
      worst = std::max(worst, std::abs(cgal[v] - exact));
    }
    std::printf("[ CGAL ref ] bump-domain %-24s max|cgal - euclid| = %.3e\n",
                SurfacePointToString(sources[0]).c_str(), worst);
  }
}

TEST(CgalReferenceTest, OtherComponentsAndIsolatedVerticesAreInfinite) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 3;
  MeshData m = MakeGrid(spec);  // 16 vertices
  MeshData second = m;
  ApplyRigidMotion(&second, {0, 0, 1}, 0, {5, 0, 0});
  for (uint32_t v : second.faces) m.faces.push_back(v + 16);
  m.positions.insert(m.positions.end(), second.positions.begin(), second.positions.end());
  m.positions.insert(m.positions.end(), {9, 9, 9});  // vertex 32, in no face
  const std::vector<double> d = CgalDistances(m, {SurfacePoint::AtVertex(5)});
  ASSERT_EQ(d.size(), 33u);
  for (uint32_t v = 0; v < 16; ++v) {
    EXPECT_NEAR(d[v], Distance3(VertexPosition(m, 5), VertexPosition(m, v)), 1e-14) << v;
  }
  for (uint32_t v = 16; v < 33; ++v) EXPECT_EQ(d[v], kInf) << v;
  // Bad sources give an empty result rather than nonsense.
  EXPECT_TRUE(CgalDistances(m, {SurfacePoint::AtVertex(32)}).empty());
  EXPECT_TRUE(CgalDistances(m, {SurfacePoint::OnEdge(0, 15, 0.5)}).empty());
}

}  // namespace
}  // namespace geodex
