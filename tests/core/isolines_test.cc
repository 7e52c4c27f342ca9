// Approximate isolines (paper section 6.1): circles on a flat square, no crossings between levels,
// closed on a closed mesh (Theorem 3), levels exactly at vertex values, edge cases.

#include "geodex/isolines.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "geodex/geodesic_solver.h"
#include "geodex/geometry_queries.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

[[noreturn]] void Abort(const char* what, const absl::Status& status) {
  std::fprintf(stderr, "%s: %s\n", what, std::string(status.message()).c_str());
  std::abort();
}

struct Fixture {
  MeshData data;
  TriangleMesh mesh;
  DistanceField field;
};

Fixture Solve(MeshData data, const std::vector<SurfacePoint>& sources) {
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  // A helper that returns cannot ASSERT: stop here rather than read an error's value.
  if (!mesh.ok()) Abort("the fixture mesh does not build", mesh.status());
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sources);
  if (!field.ok()) Abort("the fixture field does not solve", field.status());
  return Fixture{std::move(data), *std::move(mesh), *std::move(field)};
}

// The 60 x 60 unit square, jittered, alternating diagonals; vertex (i, j) is j * 61 + i.
MeshData Square(double jitter = 0.15) {
  GridSpec spec;
  spec.cells_x = spec.cells_y = 60;
  spec.alternate_diagonals = true;
  spec.jitter = jitter;
  return MakeGrid(spec);
}
uint32_t GridVertex(int i, int j) { return static_cast<uint32_t>(j * 61 + i); }

// Checks what every point claims: it lies on its edge at parameter t, below/at-or-above.
void CheckPoints(const Fixture& fx, const Isolines& iso) {
  for (const IsolinePolyline& line : iso.polylines) {
    for (const PathPoint& p : line.points) {
      ASSERT_EQ(p.where.kind, SurfacePoint::Kind::kEdge);
      const uint32_t a = p.where.edge_from, b = p.where.edge_to;
      EXPECT_LT(fx.field.distance[a], line.level);
      EXPECT_GE(fx.field.distance[b], line.level);
      EXPECT_GE(p.where.t, 0);  // 0 or 1: snapped onto the vertex
      EXPECT_LE(p.where.t, 1);
      const Vec3 pa = VertexPosition(fx.data, a), pb = VertexPosition(fx.data, b);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(p.position[k], pa[k] + p.where.t * (pb[k] - pa[k]), 1e-12);
      }
      // Linear interpolation of the distance along the edge gives the level.
      const double da = fx.field.distance[a], db = fx.field.distance[b];
      EXPECT_NEAR(da + p.where.t * (db - da), line.level, 1e-12);
    }
  }
}

TEST(IsolinesTest, SingleSourceOnFlatSquareGivesCircles) {
  const Fixture fx = Solve(Square(), {SurfacePoint::AtVertex(GridVertex(30, 30))});
  const Vec3 c = VertexPosition(fx.data, GridVertex(30, 30));
  IsolineOptions options;
  options.levels = {0.4, 0.1, 0.2, 0.3};
  absl::StatusOr<Isolines> iso = ExtractIsolines(fx.mesh, fx.field, options);
  ASSERT_TRUE(iso.ok()) << iso.status();
  EXPECT_EQ(iso->levels, (std::vector<double>{0.1, 0.2, 0.3, 0.4}));
  ASSERT_EQ(iso->polylines.size(), 4u);  // one circle per level
  CheckPoints(fx, *iso);
  // Linear interpolation of r = |x - c| along an edge of length h overestimates by at most
  // h^2 / (8 r): about 0.05 h at r = 0.1 here. A wrong parameter would be off by up to h / 2.
  const double h = fx.mesh.MaxEdgeLength();
  for (size_t i = 0; i < 4; ++i) {
    const IsolinePolyline& line = iso->polylines[i];
    EXPECT_EQ(line.level, iso->levels[i]);
    EXPECT_TRUE(line.closed);
    EXPECT_GT(line.points.size(), 20u);
    double signed_area = 0, worst = 0;
    for (size_t k = 0; k < line.points.size(); ++k) {
      const auto& p = line.points[k].position;
      const auto& q = line.points[(k + 1) % line.points.size()].position;
      worst = std::max(worst, std::abs(std::hypot(p[0] - c[0], p[1] - c[1]) - line.level));
      signed_area += 0.5 * ((p[0] - c[0]) * (q[1] - c[1]) - (q[0] - c[0]) * (p[1] - c[1]));
    }
    EXPECT_LT(worst, 0.1 * h) << "level " << line.level;
    // Counter-clockwise (the source on the left) and enclosing about pi r^2.
    EXPECT_NEAR(signed_area, M_PI * line.level * line.level, 0.01 * line.level);
  }
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

TEST(IsolinesTest, DifferentLevelsDoNotIntersect) {
  // Three sources: the level sets are unions of arcs meeting at corners.
  const Fixture fx = Solve(Square(), {SurfacePoint::AtVertex(GridVertex(10, 12)),
                                      SurfacePoint::AtVertex(GridVertex(45, 20)),
                                      SurfacePoint::AtVertex(GridVertex(25, 50))});
  IsolineOptions options;
  options.count = 30;
  absl::StatusOr<Isolines> iso = ExtractIsolines(fx.mesh, fx.field, options);
  ASSERT_TRUE(iso.ok()) << iso.status();
  EXPECT_EQ(iso->levels.size(), 29u);
  CheckPoints(fx, *iso);
  struct Seg {
    std::array<double, 3> a, b;
    double level;
  };
  std::vector<Seg> segs;
  for (const IsolinePolyline& line : iso->polylines) {
    const size_t n = line.points.size();
    for (size_t k = 0; k + (line.closed ? 0 : 1) < n; ++k) {
      segs.push_back({line.points[k].position, line.points[(k + 1) % n].position, line.level});
    }
  }
  ASSERT_GT(segs.size(), 1000u);
  std::sort(segs.begin(), segs.end(), [](const Seg& x, const Seg& y) {
    return std::min(x.a[0], x.b[0]) < std::min(y.a[0], y.b[0]);
  });
  int crossings = 0;
  for (size_t i = 0; i < segs.size(); ++i) {
    const double right = std::max(segs[i].a[0], segs[i].b[0]);
    for (size_t j = i + 1; j < segs.size() && std::min(segs[j].a[0], segs[j].b[0]) <= right; ++j) {
      if (segs[i].level != segs[j].level && Cross2d(segs[i].a, segs[i].b, segs[j].a, segs[j].b)) {
        ++crossings;
      }
    }
  }
  EXPECT_EQ(crossings, 0);
}

TEST(IsolinesTest, EveryIsolineOnAClosedMeshIsClosed) {
  for (const char* name : {"kitten.off", "bunny-npm.off"}) {
    absl::StatusOr<MeshData> data = LoadTestMeshData(name);
    ASSERT_TRUE(data.ok()) << data.status();
    const Fixture fx = Solve(*data, {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(1234)});
    ASSERT_EQ(fx.mesh.report().boundary_edges, 0u) << name;  // Theorem 3 is about closed meshes
    IsolineOptions options;
    options.count = 12;
    absl::StatusOr<Isolines> iso = ExtractIsolines(fx.mesh, fx.field, options);
    ASSERT_TRUE(iso.ok()) << iso.status();
    CheckPoints(fx, *iso);
    EXPECT_GE(iso->polylines.size(), 11u) << name;
    for (const IsolinePolyline& line : iso->polylines) {
      EXPECT_TRUE(line.closed) << name << " level " << line.level;
    }
  }
}

TEST(IsolinesTest, LevelsExactlyAtVertexValuesGiveNoDuplicatePoints) {
  // Unjittered grid: the level equals the distance of many vertices (the source's axis
  // neighbours at exactly h, and the vertices at 2h, ...).
  const Fixture fx = Solve(Square(0), {SurfacePoint::AtVertex(GridVertex(30, 30))});
  const double h = 1.0 / 60;
  IsolineOptions options;
  options.levels = {fx.field.distance[GridVertex(31, 30)], fx.field.distance[GridVertex(32, 30)],
                    fx.field.distance[GridVertex(33, 31)], 0.25};
  absl::StatusOr<Isolines> iso = ExtractIsolines(fx.mesh, fx.field, options);
  ASSERT_TRUE(iso.ok()) << iso.status();
  CheckPoints(fx, *iso);
  ASSERT_EQ(iso->polylines.size(), 4u);
  int vertex_hits = 0;
  for (const IsolinePolyline& line : iso->polylines) {
    EXPECT_TRUE(line.closed) << line.level;
    const size_t n = line.points.size();
    ASSERT_GE(n, 4u);
    for (size_t k = 0; k < n; ++k) {
      const auto& p = line.points[k].position;
      const auto& q = line.points[(k + 1) % n].position;
      EXPECT_GT(std::hypot(p[0] - q[0], p[1] - q[1]), 1e-9 * h)
          << "duplicate point, level " << line.level;
      if (line.points[k].where.t == 1 || line.points[k].where.t == 0) ++vertex_hits;
    }
  }
  EXPECT_GT(vertex_hits, 8);  // the levels really do pass through vertices
}

TEST(IsolinesTest, EmptyAndInvalidRequests) {
  const Fixture fx = Solve(Square(), {SurfacePoint::AtVertex(GridVertex(30, 30))});
  IsolineOptions options;
  options.levels = {-1, 0, 10};  // at or beyond the range of distances: nothing
  absl::StatusOr<Isolines> iso = ExtractIsolines(fx.mesh, fx.field, options);
  ASSERT_TRUE(iso.ok());
  EXPECT_TRUE(iso->polylines.empty());
  options.levels = {std::nan("")};
  EXPECT_EQ(ExtractIsolines(fx.mesh, fx.field, options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.levels = {std::numeric_limits<double>::infinity()};
  EXPECT_EQ(ExtractIsolines(fx.mesh, fx.field, options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.levels.clear();
  options.count = 1;
  EXPECT_EQ(ExtractIsolines(fx.mesh, fx.field, options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.count = 4;
  DistanceField wrong = fx.field;
  wrong.internal_distance.pop_back();
  EXPECT_EQ(ExtractIsolines(fx.mesh, wrong, options).status().code(),
            absl::StatusCode::kInvalidArgument);
  // count K: K - 1 levels D j / K strictly inside (0, D).
  iso = ExtractIsolines(fx.mesh, fx.field, options);
  ASSERT_TRUE(iso.ok());
  const double d_max = *std::max_element(fx.field.distance.begin(), fx.field.distance.end());
  ASSERT_EQ(iso->levels.size(), 3u);
  for (int j = 1; j <= 3; ++j) EXPECT_DOUBLE_EQ(iso->levels[j - 1], d_max * j / 4);
}

// The one check of isoline options names the option, and tells a bad value from one over a limit.
TEST(IsolinesTest, ValidateIsolineOptionsNamesTheOption) {
  IsolineOptions options;
  options.levels = {1, std::nan(""), 2};
  absl::Status s = ValidateIsolineOptions(options);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(InvalidOptionOf(s), "levels[1]");
  options.levels = {1, 2, 3};
  EXPECT_TRUE(ValidateIsolineOptions(options, 3).ok());
  s = ValidateIsolineOptions(options, 2);
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(InvalidOptionOf(s), "levels");
  options.levels.clear();
  options.count = 1;
  s = ValidateIsolineOptions(options);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(InvalidOptionOf(s), "count");
  options.count = 4;  // 3 levels
  EXPECT_TRUE(ValidateIsolineOptions(options, 3).ok());
  s = ValidateIsolineOptions(options, 2);
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(InvalidOptionOf(s), "count");
}

// A geometry query carries its field's solver options: lambda reaches the field the isolines are
// drawn on (lambda = 1 is Dijkstra's field, whose levels differ from the exact ones), and the
// isolines equal those extracted from the field solved with the same options.
TEST(IsolinesTest, IsolineQueryCarriesTheSolverOptions) {
  const MeshData data = Square();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  IsolineQuery query{{SurfacePoint::AtVertex(GridVertex(30, 30))}, {}, {}};
  query.levels.count = 5;
  absl::StatusOr<Isolines> exact = ComputeIsolines(*mesh, query);
  query.options.lambda = 1;
  absl::StatusOr<Isolines> graph = ComputeIsolines(*mesh, query);
  ASSERT_TRUE(exact.ok() && graph.ok());
  EXPECT_NE(exact->levels, graph->levels);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, query.sources, query.options);
  ASSERT_TRUE(field.ok());
  absl::StatusOr<Isolines> direct = ExtractIsolines(*mesh, *field, query.levels);
  ASSERT_TRUE(direct.ok());
  EXPECT_EQ(direct->levels, graph->levels);
  ASSERT_EQ(direct->polylines.size(), graph->polylines.size());
  for (size_t i = 0; i < direct->polylines.size(); ++i) {
    ASSERT_EQ(direct->polylines[i].points.size(), graph->polylines[i].points.size());
  }
  query.options.lambda = 2;
  EXPECT_EQ(InvalidOptionOf(ComputeIsolines(*mesh, query).status()), "lambda");
  query.options.lambda = 0;
  query.levels.count = 1;
  EXPECT_EQ(InvalidOptionOf(ComputeIsolines(*mesh, query).status()), "count");
}

TEST(IsolinesTest, UnreachableComponentGetsNoIsolinesAndCutLinesAreOpen) {
  // Two squares side by side, not connected; the source is in the first one.
  MeshData a = Square(), b = Square();
  const uint32_t offset = static_cast<uint32_t>(a.vertex_count());
  for (size_t i = 0; i < b.positions.size(); ++i) {
    a.positions.push_back(b.positions[i] + (i % 3 == 0 ? 2 : 0));
  }
  for (uint32_t v : b.faces) a.faces.push_back(v + offset);
  const Fixture fx = Solve(a, {SurfacePoint::AtVertex(GridVertex(5, 5))});
  IsolineOptions options;
  options.count = 6;
  absl::StatusOr<Isolines> iso = ExtractIsolines(fx.mesh, fx.field, options);
  ASSERT_TRUE(iso.ok()) << iso.status();
  CheckPoints(fx, *iso);
  ASSERT_EQ(iso->polylines.size(), 5u);
  for (const IsolinePolyline& line : iso->polylines) {
    EXPECT_FALSE(line.closed);  // arcs around a corner source end on the square's border
    for (const PathPoint& p : line.points) EXPECT_LT(p.where.edge_to, offset);
  }
}

}  // namespace
}  // namespace geodex
