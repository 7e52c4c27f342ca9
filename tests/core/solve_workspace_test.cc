// The engine's per-solve arrays are reused between solves on a mesh (ich/solve_workspace.h): a
// targeted solve resets only what the previous one touched. A leak from one solve into the next
// would change answers, so every query here runs on a mesh that has already answered others and
// on a freshly built copy, and the two must agree bit for bit, counters included.

#include "ich/solve_workspace.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/shortest_path.h"
#include "gtest/gtest.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

// Everything a query's answer consists of, flattened for comparison.
struct Answer {
  std::vector<double> values;
  uint64_t windows_created = 0;
  uint64_t windows_processed = 0;
};

// A mixed sequence: A* paths near and far, from vertices, edge and face points; matrices; exact
// distances at points; full fields (one with max_distance, one with lambda, one with the paper's
// tree); early stops in between, so the next solve starts after a partial one.
std::vector<Answer> RunQueries(const TriangleMesh& mesh) {
  std::vector<Answer> out;
  const uint32_t nv = mesh.file_vertex_count();
  const uint32_t nf = mesh.face_count();
  auto add_path = [&](const SurfacePoint& a, const SurfacePoint& b, const PathQueryOptions& o) {
    absl::StatusOr<PathQueryResult> r = ComputeShortestPath(mesh, a, b, o);
    Answer ans;
    if (r.ok()) {
      ans.values.push_back(r->distance);
      for (const PathPoint& p : r->path.points) {
        ans.values.insert(ans.values.end(), p.position.begin(), p.position.end());
      }
      ans.windows_created = r->stats.windows_created;
      ans.windows_processed = r->stats.windows_processed;
    } else {
      ans.values.push_back(-static_cast<double>(r.status().code()));
    }
    out.push_back(ans);
  };
  auto add_field = [&](const std::vector<SurfacePoint>& sources, const GeodesicOptions& o) {
    absl::StatusOr<DistanceField> f = ComputeDistanceField(mesh, sources, o);
    Answer ans;
    if (f.ok()) {
      ans.values = f->distance;
      for (uint32_t s : f->source) ans.values.push_back(s);
      ans.windows_created = f->stats.windows_created;
      ans.windows_processed = f->stats.windows_processed;
    }
    out.push_back(ans);
  };
  PathQueryOptions astar;
  PathQueryOptions dijkstra_order;  // no heuristic: plain early stop
  dijkstra_order.use_heuristic = false;
  PathQueryOptions capped;
  capped.solver.max_distance = 0.3 * (mesh.BoundsMax()[0] - mesh.BoundsMin()[0]);
  for (uint32_t i = 0; i < 6; ++i) {
    const uint32_t a = (i * 7919u) % nv, b = (i * 104729u + 17) % nv;
    add_path(SurfacePoint::AtVertex(a), SurfacePoint::AtVertex(b), astar);
    add_path(SurfacePoint::InFace((i * 31u) % nf, 0.2, 0.3, 0.5),
             SurfacePoint::AtVertex((a + 1) % nv), i % 2 ? astar : dijkstra_order);
    add_path(SurfacePoint::AtVertex(b),
             SurfacePoint::OnEdge(mesh.FaceVertex(i % nf, 0), mesh.FaceVertex(i % nf, 1), 0.4),
             i % 2 ? dijkstra_order : capped);
    if (i == 2) {
      GeodesicOptions capped_field;
      capped_field.max_distance = capped.solver.max_distance;
      add_field({SurfacePoint::AtVertex(a)}, capped_field);
      GeodesicOptions coarse;
      coarse.lambda = 0.2;
      add_field({SurfacePoint::AtVertex(b), SurfacePoint::InFace(0, 0.3, 0.3, 0.4)}, coarse);
    }
    if (i == 4) {
      GeodesicOptions paper;
      paper.method = Method::kIch;
      add_field({SurfacePoint::AtVertex(a)}, paper);
      PathQueryOptions paper_path;
      paper_path.solver.method = Method::kIch;
      add_path(SurfacePoint::AtVertex(a), SurfacePoint::AtVertex(b), paper_path);
    }
  }
  std::vector<SurfacePoint> points;
  for (uint32_t k = 0; k < 5; ++k) {
    points.push_back(k % 2 ? SurfacePoint::AtVertex((k * 97u) % nv)
                           : SurfacePoint::InFace((k * 53u) % nf, 0.6, 0.2, 0.2));
  }
  absl::StatusOr<DistanceMatrix> m = ComputeDistanceMatrix(mesh, points, points);
  Answer matrix;
  if (m.ok()) matrix.values = m->values;
  out.push_back(matrix);
  absl::StatusOr<std::vector<std::pair<double, uint32_t>>> at =
      ComputeExactDistancesAt(mesh, {points[0], points[3]}, points);
  Answer exact_at;
  if (at.ok()) {
    for (const auto& [d, label] : *at) {
      exact_at.values.push_back(d);
      exact_at.values.push_back(label);
    }
  }
  out.push_back(exact_at);
  return out;
}

class SolveWorkspaceTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SolveWorkspaceTest, AnswersOnAWarmMeshEqualThoseOnAFreshOne) {
  absl::StatusOr<TriangleMesh> warm = LoadTestMesh(GetParam());
  ASSERT_TRUE(warm.ok()) << warm.status();
  // Warm the mesh's workspaces with the whole sequence once, then run it again.
  const std::vector<Answer> first = RunQueries(*warm);
  const std::vector<Answer> again = RunQueries(*warm);
  // The reference: each query alone on a mesh that has never solved anything.
  ASSERT_EQ(first.size(), again.size());
  std::vector<Answer> fresh;
  {
    absl::StatusOr<TriangleMesh> cold = LoadTestMesh(GetParam());
    ASSERT_TRUE(cold.ok());
    fresh = RunQueries(*cold);  // within it, later queries are warm too: compare to `again` below
  }
  for (size_t q = 0; q < first.size(); ++q) {
    SCOPED_TRACE("query " + std::to_string(q));
    ASSERT_FALSE(first[q].values.empty());
    EXPECT_EQ(first[q].values, again[q].values);
    EXPECT_EQ(first[q].values, fresh[q].values);
    EXPECT_EQ(first[q].windows_created, again[q].windows_created);
    EXPECT_EQ(first[q].windows_processed, again[q].windows_processed);
  }
  // And the first query of the sequence, cold, against the same query run last of all, warm.
  {
    absl::StatusOr<TriangleMesh> cold = LoadTestMesh(GetParam());
    ASSERT_TRUE(cold.ok());
    const PathQueryResult a =
        *ComputeShortestPath(*cold, SurfacePoint::AtVertex(0),
                             SurfacePoint::AtVertex(104729u % warm->file_vertex_count()));
    const PathQueryResult b =
        *ComputeShortestPath(*warm, SurfacePoint::AtVertex(0),
                             SurfacePoint::AtVertex(104729u % warm->file_vertex_count()));
    EXPECT_EQ(a.distance, b.distance);
    EXPECT_EQ(a.stats.windows_created, b.stats.windows_created);
    EXPECT_EQ(a.path.points.size(), b.path.points.size());
  }
}

TEST_P(SolveWorkspaceTest, ThreadsSharingAMeshGetTheAnswersOfOne) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<Answer> alone = RunQueries(*mesh);
  std::vector<Answer> in_thread[2];
  std::thread t0([&] { in_thread[0] = RunQueries(*mesh); });
  std::thread t1([&] { in_thread[1] = RunQueries(*mesh); });
  t0.join();
  t1.join();
  for (const auto& answers : in_thread) {
    ASSERT_EQ(answers.size(), alone.size());
    for (size_t q = 0; q < alone.size(); ++q) EXPECT_EQ(answers[q].values, alone[q].values) << q;
  }
}

TEST_P(SolveWorkspaceTest, IdleMemoryFollowsTheMeshNotTheWork) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(GetParam());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_NE(mesh->workspaces(), nullptr);
  EXPECT_EQ(mesh->workspaces()->IdleBytes(), 0u);
  // A full field's window pool and queue are larger than anything a later solve needs to keep.
  ASSERT_TRUE(ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)}).ok());
  const uint64_t v = mesh->vertex_count(), f = mesh->face_count();
  // Per vertex: distance, label, origin, two flags, a touched entry; per half-edge: a Lemma 1
  // record and a touched entry; per face: a target list head. Twice that for vector slack.
  const uint64_t per_mesh = 2 * (v * (8 + 4 + 24 + 1 + 1 + 4) + 3 * f * (16 + 4) + f * 4);
  EXPECT_GT(mesh->workspaces()->IdleBytes(), 0u);
  EXPECT_LE(mesh->workspaces()->IdleBytes(), per_mesh);
  RunQueries(*mesh);
  // One workspace per solve that ran at once: the matrix's 5 rows ran on up to every core. Each
  // keeps its mesh arrays and at most as many bytes again of window pool and queue (Release
  // frees larger ones), whatever the work was.
  const uint64_t at_once = std::max(1u, std::min(UsableCores(), 5u));
  EXPECT_LE(mesh->workspaces()->IdleBytes(), at_once * 2 * per_mesh);
}

INSTANTIATE_TEST_SUITE_P(CommittedMeshes, SolveWorkspaceTest,
                         ::testing::Values("knight.off", "kitten.off", "bump-domain.off"),
                         MeshFileParamName());

}  // namespace
}  // namespace geodex
