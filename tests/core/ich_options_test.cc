// ICH options: surface-point sources, the lambda knob (paper section 7), max_distance,
// cancellation and the window budget.

#include <algorithm>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "geodex/cancel.h"
#include "geodex/geodesic_solver.h"
#include "gtest/gtest.h"
#include "util/mesh_factory.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

DistanceField Solve(const TriangleMesh& mesh, const std::vector<SurfacePoint>& sources,
                    const GeodesicOptions& options = {}) {
  absl::StatusOr<DistanceField> f = ComputeDistanceField(mesh, sources, options);
  EXPECT_TRUE(f.ok()) << f.status();
  return f.ok() ? *std::move(f) : DistanceField{};
}

double MaxFinite(const std::vector<double>& d) {
  double m = 0;
  for (double x : d) {
    if (std::isfinite(x)) m = std::max(m, x);
  }
  return m;
}

class LambdaTest : public ::testing::TestWithParam<std::string> {};

TEST_P(LambdaTest, DistancesLieBetweenExactAndDijkstraAndCoarsenMonotonically) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<SurfacePoint> src = {SurfacePoint::AtVertex(0)};
  const DistanceField exact = Solve(*mesh, src);
  GeodesicOptions dj;
  dj.method = Method::kDijkstra;
  const DistanceField dijkstra = Solve(*mesh, src, dj);
  const double scale = MaxFinite(exact.distance);
  uint64_t previous_windows = UINT64_MAX;
  double previous_error = -1;
  for (double lambda : {0.0, 0.02, 0.1, 0.3, 1.0}) {
    SCOPED_TRACE("lambda " + std::to_string(lambda));
    GeodesicOptions o;
    o.lambda = lambda;
    const DistanceField f = Solve(*mesh, src, o);
    double error = 0;
    for (size_t v = 0; v < f.distance.size(); ++v) {
      ASSERT_GE(f.distance[v], exact.distance[v] - 1e-12 * scale) << "vertex " << v;
      ASSERT_LE(f.distance[v], dijkstra.distance[v] + 1e-12 * scale) << "vertex " << v;
      error = std::max(error, f.distance[v] - exact.distance[v]);
    }
    // Over-filtering removes windows and can only lose precision as lambda grows.
    EXPECT_LE(f.stats.windows_processed, previous_windows);
    EXPECT_GE(error, previous_error - 1e-12 * scale);
    previous_windows = f.stats.windows_processed;
    previous_error = error;
  }
  EXPECT_GT(previous_error, 0);  // lambda = 1 is Dijkstra, visibly worse than exact here
}

TEST_P(LambdaTest, LambdaOneWithMaxEdgeScaleIsExactlyDijkstra) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<SurfacePoint> src = {SurfacePoint::AtVertex(0),
                                         SurfacePoint::AtVertex(mesh->file_vertex_count() / 2)};
  GeodesicOptions dj;
  dj.method = Method::kDijkstra;
  const DistanceField dijkstra = Solve(*mesh, src, dj);
  GeodesicOptions o;
  o.lambda = 1;
  o.lambda_scale = LambdaScale::kMaxEdge;
  const DistanceField f = Solve(*mesh, src, o);
  for (size_t v = 0; v < f.distance.size(); ++v) {
    ASSERT_EQ(f.distance[v], dijkstra.distance[v]) << "vertex " << v;  // bit for bit (Theorem 8)
  }
  EXPECT_EQ(f.stats.windows_processed, 0u);
}

TEST_P(LambdaTest, MeanEdgeScaleStaysBetweenExactAndDijkstra) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<SurfacePoint> src = {SurfacePoint::AtVertex(0)};
  const DistanceField exact = Solve(*mesh, src);
  GeodesicOptions dj;
  dj.method = Method::kDijkstra;
  const DistanceField dijkstra = Solve(*mesh, src, dj);
  GeodesicOptions o;
  o.lambda = 0.5;
  o.lambda_scale = LambdaScale::kMeanEdge;
  const DistanceField f = Solve(*mesh, src, o);
  const double scale = MaxFinite(exact.distance);
  for (size_t v = 0; v < f.distance.size(); ++v) {
    ASSERT_GE(f.distance[v], exact.distance[v] - 1e-12 * scale);
    ASSERT_LE(f.distance[v], dijkstra.distance[v] + 1e-12 * scale);
  }
  EXPECT_LT(f.stats.windows_processed, exact.stats.windows_processed);
}

INSTANTIATE_TEST_SUITE_P(Meshes, LambdaTest,
                         ::testing::Values("kitten.off", "three-peaks.off", "bunny-npm.off"),
                         [](const auto& info) {
                           std::string n = info.param;
                           std::replace(n.begin(), n.end(), '.', '_');
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

TEST(MaxDistanceTest, VerticesBeyondTheBoundAreUnreachableAndTheRestExact) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("fertility.off");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<SurfacePoint> src = {SurfacePoint::AtVertex(100)};
  const DistanceField exact = Solve(*mesh, src);
  const double bound = 0.3 * MaxFinite(exact.distance);
  GeodesicOptions o;
  o.max_distance = bound;
  const DistanceField f = Solve(*mesh, src, o);
  size_t inside = 0;
  for (size_t v = 0; v < f.distance.size(); ++v) {
    if (exact.distance[v] <= bound * (1 - 1e-12)) {
      ++inside;
      EXPECT_EQ(f.distance[v], exact.distance[v]) << "vertex " << v;
      EXPECT_EQ(f.source[v], 0u);
    } else if (exact.distance[v] > bound * (1 + 1e-12)) {
      EXPECT_TRUE(std::isinf(f.distance[v])) << "vertex " << v << " at " << f.distance[v];
      EXPECT_EQ(f.source[v], kNoIndex);
    }
  }
  EXPECT_GT(inside, 10u);
  EXPECT_LT(inside, f.distance.size());
  EXPECT_LT(f.stats.windows_created, exact.stats.windows_created / 2);
}

TEST(MaxDistanceTest, RejectsNonPositiveBounds) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok());
  GeodesicOptions o;
  o.max_distance = 0;
  absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, o);
  EXPECT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(InvalidOptionOf(f.status()), "max_distance");  // the option as data, for front ends
}

TEST(OptionsTest, OneCheckNamesTheOption) {
  GeodesicOptions o;
  EXPECT_TRUE(ValidateGeodesicOptions(o).ok());
  o.lambda = std::nan("");
  absl::Status s = ValidateGeodesicOptions(o);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(InvalidOptionOf(s), "lambda");
  o.lambda = 1;
  o.max_distance = -2;
  EXPECT_EQ(InvalidOptionOf(ValidateGeodesicOptions(o)), "max_distance");
  EXPECT_EQ(InvalidOptionOf(absl::InvalidArgumentError("lambda: no payload")), "");
}

TEST(CancellationTest, CancelledTokenStopsTheSolveAndTheThreadServesTheNextOne) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("fertility.off");
  ASSERT_TRUE(mesh.ok());
  const std::vector<SurfacePoint> src = {SurfacePoint::AtVertex(0)};
  CancelToken token;
  token.Cancel();
  GeodesicOptions o;
  o.cancel = &token;
  for (Method method : {Method::kIch, Method::kDijkstra}) {
    o.method = method;
    absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, src, o);
    EXPECT_EQ(f.status().code(), absl::StatusCode::kCancelled) << f.status();
  }
  // The same thread solves again with a fresh token, correctly.
  CancelToken fresh;
  o.cancel = &fresh;
  o.method = Method::kIch;
  const DistanceField again = Solve(*mesh, src, o);
  const DistanceField reference = Solve(*mesh, src);
  EXPECT_EQ(again.distance, reference.distance);
}

TEST(CancellationTest, CancelFromAnotherThreadEndsTheSolve) {
  // A fine grid keeps the solve busy (tens of milliseconds, far longer than starting a thread):
  // the worker must come back cancelled, or, if it won the race, with the exact field; and across
  // a few tries the cancel must land at least once.
  GridSpec spec;
  spec.cells_x = spec.cells_y = 160;
  spec.jitter = 0.3;
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(MakeGrid(spec));
  ASSERT_TRUE(mesh.ok());
  const DistanceField reference = Solve(*mesh, {SurfacePoint::AtVertex(0)});
  int cancelled = 0;
  for (int attempt = 0; attempt < 5; ++attempt) {
    CancelToken token;
    GeodesicOptions o;
    o.cancel = &token;
    absl::StatusOr<DistanceField> field;
    std::thread worker(
        [&] { field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, o); });
    token.Cancel();
    worker.join();
    if (field.ok()) {
      EXPECT_EQ(field->distance, reference.distance);  // finished first: the exact answer
    } else {
      ASSERT_EQ(field.status().code(), absl::StatusCode::kCancelled) << field.status();
      ++cancelled;
    }
  }
  EXPECT_GT(cancelled, 0) << "five solves of a 51k-face grid all finished before Cancel()";
}

TEST(WindowBudgetTest, ExceedingTheBudgetIsAClearError) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("kitten.off");
  ASSERT_TRUE(mesh.ok());
  GeodesicOptions o;
  o.max_windows = 1000;
  absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, o);
  ASSERT_EQ(f.status().code(), absl::StatusCode::kResourceExhausted) << f.status();
  EXPECT_NE(f.status().message().find("window budget"), std::string::npos) << f.status();
  o.max_windows = 10'000'000;
  EXPECT_TRUE(ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}, o).ok());
}

// Surface points that coincide must give the same field, whichever way they are written.
TEST(SurfacePointTest, EquivalentSpellingsGiveTheSameField) {
  absl::StatusOr<MeshData> data = LoadTestMeshData("bunny-npm.off");
  ASSERT_TRUE(data.ok());
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok());
  const uint32_t f = 123;
  const uint32_t a = data->faces[3 * f], b = data->faces[3 * f + 1], c = data->faces[3 * f + 2];
  const double scale = MaxFinite(Solve(*mesh, {SurfacePoint::AtVertex(a)}).distance);
  auto expect_same = [&](const SurfacePoint& p, const SurfacePoint& q, double tol) {
    const DistanceField fp = Solve(*mesh, {p});
    const DistanceField fq = Solve(*mesh, {q});
    for (size_t v = 0; v < fp.distance.size(); ++v) {
      ASSERT_NEAR(fp.distance[v], fq.distance[v], tol * scale)
          << SurfacePointToString(p) << " vs " << SurfacePointToString(q) << " at vertex " << v;
    }
  };
  // A vertex as a vertex, an edge end and a face corner: identical.
  expect_same(SurfacePoint::AtVertex(a), SurfacePoint::OnEdge(a, b, 0), 0);
  expect_same(SurfacePoint::AtVertex(b), SurfacePoint::OnEdge(a, b, 1), 0);
  expect_same(SurfacePoint::AtVertex(c), SurfacePoint::InFace(f, 0, 0, 1), 0);
  // An edge point given on the edge (either direction) and as a face point on that edge.
  expect_same(SurfacePoint::OnEdge(a, b, 0.3), SurfacePoint::OnEdge(b, a, 0.7), 1e-12);
  expect_same(SurfacePoint::OnEdge(a, b, 0.3), SurfacePoint::InFace(f, 0.7, 0.3, 0), 1e-12);
  expect_same(SurfacePoint::OnEdge(b, c, 0.25), SurfacePoint::InFace(f, 0, 0.75, 0.25), 1e-12);
}

TEST(SurfacePointTest, FacePointDistancesToItsCornersAreStraight) {
  absl::StatusOr<MeshData> data = LoadTestMeshData("kitten.off");
  ASSERT_TRUE(data.ok());
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  ASSERT_TRUE(mesh.ok());
  const uint32_t f = 777;
  const double w[3] = {0.2, 0.5, 0.3};
  Vec3 p{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const Vec3 q = VertexPosition(*data, data->faces[3 * f + k]);
    for (int i = 0; i < 3; ++i) p[i] += w[k] * q[i];
  }
  const DistanceField field = Solve(*mesh, {SurfacePoint::InFace(f, w[0], w[1], w[2])});
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = data->faces[3 * f + k];
    EXPECT_NEAR(field.distance[v], Distance3(p, VertexPosition(*data, v)), 1e-14);
  }
}

TEST(SurfacePointTest, BadPointsAreRejectedNamingTheItem) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok());
  struct Case {
    SurfacePoint p;
    std::string naming;
  };
  const Case cases[] = {
      {SurfacePoint::AtVertex(502), "vertex 502"},
      {SurfacePoint::OnEdge(0, 1, -0.5), "outside [0, 1]"},
      {SurfacePoint::OnEdge(0, 400, 0.5), "no edge between vertices 0 and 400"},
      {SurfacePoint::InFace(1000, 1, 0, 0), "face 1000"},
      {SurfacePoint::InFace(3, 0.5, 0.6, -0.1), "negative"},
      {SurfacePoint::InFace(3, 0.5, 0.6, 0.1), "sum to"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<DistanceField> f = ComputeDistanceField(*mesh, {c.p});
    ASSERT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument) << SurfacePointToString(c.p);
    EXPECT_NE(f.status().message().find(c.naming), std::string::npos) << f.status();
  }
  EXPECT_EQ(ComputeDistanceField(*mesh, {}).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(SurfacePointTest, ParserNamesTheBadItem) {
  EXPECT_TRUE(ParseSurfacePoints("17,e:1:2:0.5,f:3:0.2:0.3:0.5").ok());
  for (const char* bad : {"", "x", "e:1:2", "f:1:0.5:0.5", "17,,3", "-1", "e:1:2:nan"}) {
    absl::StatusOr<std::vector<SurfacePoint>> p = ParseSurfacePoints(bad);
    EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument) << bad;
  }
  absl::StatusOr<std::vector<SurfacePoint>> p = ParseSurfacePoints("1,q:2");
  EXPECT_NE(p.status().message().find("q:2"), std::string::npos) << p.status();
}

}  // namespace
}  // namespace geodex

namespace geodex {
namespace {

// The default engine (no window tree, quantised queue order) and the paper's ICH are two exact
// algorithms: they must give the same field, from vertex, edge and face sources, on closed
// meshes, open ones and a flat-bottomed terrain, and the default must hold fewer live windows.
class EnginesTest : public ::testing::TestWithParam<std::string> {};

TEST_P(EnginesTest, DefaultEngineMatchesThePapersIch) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const uint32_t f = mesh->face_count() / 3;
  const std::vector<std::vector<SurfacePoint>> source_sets = {
      {SurfacePoint::AtVertex(0)},
      {SurfacePoint::InFace(f, 0.2, 0.3, 0.5)},
      {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(mesh->file_vertex_count() / 2)}};
  for (const auto& sources : source_sets) {
    GeodesicOptions paper;
    paper.method = Method::kIch;
    const DistanceField a = Solve(*mesh, sources);
    const DistanceField b = Solve(*mesh, sources, paper);
    ASSERT_EQ(a.distance.size(), b.distance.size());
    const double scale = MaxFinite(b.distance);
    ASSERT_GT(scale, 0);
    for (size_t v = 0; v < a.distance.size(); ++v) {
      ASSERT_EQ(std::isfinite(a.distance[v]), std::isfinite(b.distance[v])) << "vertex " << v;
      if (std::isfinite(b.distance[v])) {
        EXPECT_LE(std::abs(a.distance[v] - b.distance[v]), 1e-13 * scale) << "vertex " << v;
      }
      EXPECT_EQ(a.source[v], b.source[v]) << "vertex " << v;
    }
    EXPECT_LE(a.stats.peak_live_windows, b.stats.peak_live_windows);
    EXPECT_EQ(a.stats.windows_deleted_one_split, 0u);  // Lemma 1 forward only
  }
}

INSTANTIATE_TEST_SUITE_P(CommittedMeshes, EnginesTest,
                         ::testing::Values("knight.off", "kitten.off", "three-peaks.off",
                                           "bump-domain.off", "fertility.off"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name) {
                             if (c == '.' || c == '-') c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace geodex
