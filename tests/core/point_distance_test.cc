// The paper's unfolding estimate (section 4) at surface points, against exact values obtained by
// symmetry (a solve from the point itself, read at the source vertex).

#include "geodex/point_distance.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "geodex/geodesic_solver.h"
#include "gtest/gtest.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

struct Errors {
  std::vector<double> relative;
};

Errors EstimateErrors(const std::string& name, uint32_t source, int samples) {
  Errors out;
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh(name);
  EXPECT_TRUE(mesh.ok());
  absl::StatusOr<DistanceField> field =
      ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(source)});
  EXPECT_TRUE(field.ok());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.05, 1.0);
  for (int i = 0; i < samples; ++i) {
    const uint32_t f = static_cast<uint32_t>(rng() % mesh->face_count());
    double b[3] = {unit(rng), unit(rng), unit(rng)};
    const double sum = b[0] + b[1] + b[2];
    const SurfacePoint p = SurfacePoint::InFace(f, b[0] / sum, b[1] / sum, 1 - (b[0] + b[1]) / sum);
    absl::StatusOr<PointEstimate> est = EstimateDistanceAt(*mesh, *field, p);
    EXPECT_TRUE(est.ok()) << est.status();
    absl::StatusOr<DistanceField> from_point = ComputeDistanceField(*mesh, {p});
    EXPECT_TRUE(from_point.ok());
    const double exact = from_point->distance[source];
    if (exact > 0) out.relative.push_back((est->distance - exact) / exact);
    EXPECT_EQ(est->source, 0u);
  }
  return out;
}

TEST(PointEstimateTest, ExactOnAFlatConvexDomain) {
  // On a flat convex domain the unfolded image is the source itself: no error at all.
  const Errors e = EstimateErrors("bump-domain.off", 2086, 20);
  for (double r : e.relative) EXPECT_NEAR(r, 0, 1e-10);
}

TEST(PointEstimateTest, SmallErrorsOnCurvedMeshes) {
  for (const char* name : {"kitten.off", "fertility.off"}) {
    Errors e = EstimateErrors(name, 0, 30);
    std::vector<double> abs_rel;
    for (double r : e.relative) abs_rel.push_back(std::abs(r));
    std::sort(abs_rel.begin(), abs_rel.end());
    ASSERT_FALSE(abs_rel.empty());
    // The paper's claim is ~0.1% on refined meshes; these are coarse (5k-9k faces).
    EXPECT_LT(abs_rel[abs_rel.size() / 2], 5e-3) << name;
    EXPECT_LT(abs_rel.back(), 0.1) << name;
  }
}

TEST(PointEstimateTest, VerticesAndSameFaceSourcesAreExact) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("kitten.off");
  ASSERT_TRUE(mesh.ok());
  const SurfacePoint src = SurfacePoint::InFace(40, 0.6, 0.2, 0.2);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {src});
  ASSERT_TRUE(field.ok());
  // A vertex: the field's own value.
  absl::StatusOr<PointEstimate> at_vertex =
      EstimateDistanceAt(*mesh, *field, SurfacePoint::AtVertex(9));
  ASSERT_TRUE(at_vertex.ok());
  EXPECT_EQ(at_vertex->distance, field->distance[9]);
  // Another point of the source's face: a straight line.
  const SurfacePoint q = SurfacePoint::InFace(40, 0.2, 0.2, 0.6);
  absl::StatusOr<PointEstimate> same_face = EstimateDistanceAt(*mesh, *field, q);
  ASSERT_TRUE(same_face.ok());
  absl::StatusOr<DistanceField> from_q = ComputeDistanceField(*mesh, {q});
  ASSERT_TRUE(from_q.ok());
  // Distance from q to src by symmetry: the field from q evaluated (estimated) at src, which is
  // again a same-face straight line.
  absl::StatusOr<PointEstimate> back = EstimateDistanceAt(*mesh, *from_q, src);
  ASSERT_TRUE(back.ok());
  EXPECT_NEAR(same_face->distance, back->distance, 1e-14);
  EXPECT_GT(same_face->distance, 0);
}

TEST(PointEstimateTest, SeveralSourcesPickTheNearerLabel) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("bump-domain.off");
  ASSERT_TRUE(mesh.ok());
  absl::StatusOr<DistanceField> field =
      ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(2086)});
  ASSERT_TRUE(field.ok());
  // At the corner vertices of a face the labels agree with the field; the estimate inside a face
  // whose vertices all belong to one source carries that label.
  for (uint32_t f = 0; f < mesh->face_count(); f += 97) {
    const uint32_t l0 = field->source[mesh->FaceVertex(f, 0)];
    if (l0 != field->source[mesh->FaceVertex(f, 1)] ||
        l0 != field->source[mesh->FaceVertex(f, 2)]) {
      continue;
    }
    absl::StatusOr<PointEstimate> e =
        EstimateDistanceAt(*mesh, *field, SurfacePoint::InFace(f, 0.3, 0.3, 0.4));
    ASSERT_TRUE(e.ok());
    EXPECT_EQ(e->source, l0);
  }
}

TEST(PointEstimateTest, BadPointsAreErrors) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("knight.off");
  ASSERT_TRUE(mesh.ok());
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(field.ok());
  EXPECT_EQ(EstimateDistanceAt(*mesh, *field, SurfacePoint::InFace(5000, 1, 0, 0)).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(EstimateDistanceAt(*mesh, *field, SurfacePoint::OnEdge(0, 400, 0.5)).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace geodex
