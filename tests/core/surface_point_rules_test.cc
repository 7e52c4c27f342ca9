// The surface-point rules (geodex/surface_point.h: kSurfaceSnap, CanonicalFacePoint,
// CanonicalEdgePoint, TriangleMesh::SwapCornerOrder) are the only ones: a point located from its
// position, resolved as a source and placed for an estimate comes back as the same simplex and
// position, on a mesh with a flipped face and a split (non-manifold) vertex.

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "geodex/geodesic_solver.h"
#include "geodex/locate.h"
#include "geodex/point_distance.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "source_resolver.h"
#include "util/mesh_factory.h"

namespace geodex {
namespace {

using Vec3 = std::array<double, 3>;

// Two fans meeting only at vertex 0 (a bowtie, so vertex 0 is split into two internal copies),
// the first fan bent along edge 0-2 so that the surface is not a plane, and face 1 wound against
// face 0 (so Build flips it).
MeshData BentFlippedBowtie() {
  const double c = 0.5, s = std::sqrt(3.0) / 2;
  return Soup(
      {{0, 0, 0}, {c, -s, 0}, {1, 0, 0}, {c, s, 0.4}, {-c, s, 0}, {-1, 0, 0}, {-c, -s, 0.2}},
      {{0, 1, 2}, {0, 3, 2}, {0, 4, 5}, {0, 5, 6}});
}

double Dist(const Vec3& a, const Vec3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// Same simplex: the same vertex, the same edge (either direction) at the same parameter, or the
// same face at the same barycentrics, within `tol`.
::testing::AssertionResult SameSimplex(const SurfacePoint& a, const SurfacePoint& b, double tol) {
  auto fail = [&] {
    return ::testing::AssertionFailure()
           << SurfacePointToString(a) << " vs " << SurfacePointToString(b);
  };
  if (a.kind != b.kind) return fail();
  switch (a.kind) {
    case SurfacePoint::Kind::kVertex:
      return a.vertex == b.vertex ? ::testing::AssertionSuccess() : fail();
    case SurfacePoint::Kind::kEdge:
      if (a.edge_from == b.edge_from && a.edge_to == b.edge_to && std::abs(a.t - b.t) <= tol) {
        return ::testing::AssertionSuccess();
      }
      if (a.edge_from == b.edge_to && a.edge_to == b.edge_from &&
          std::abs(a.t - (1 - b.t)) <= tol) {
        return ::testing::AssertionSuccess();
      }
      return fail();
    case SurfacePoint::Kind::kFace:
      if (a.face != b.face) return fail();
      for (int k = 0; k < 3; ++k) {
        if (!(std::abs(a.bary[k] - b.bary[k]) <= tol)) return fail();
      }
      return ::testing::AssertionSuccess();
    case SurfacePoint::Kind::kPosition:
      break;
  }
  return fail();
}

struct Case {
  std::string name;
  SurfacePoint point;
  SurfacePoint::Kind expected;  // the kind of its canonical form
};

std::vector<Case> Cases() {
  using K = SurfacePoint::Kind;
  return {
      {"the split vertex", SurfacePoint::AtVertex(0), K::kVertex},
      {"a plain vertex", SurfacePoint::AtVertex(3), K::kVertex},
      {"edge t = 0", SurfacePoint::OnEdge(2, 3, 0), K::kVertex},
      {"edge t = 1e-15", SurfacePoint::OnEdge(2, 3, 1e-15), K::kVertex},
      {"edge t = 1e-12 (the tolerance itself)", SurfacePoint::OnEdge(2, 3, 1e-12), K::kVertex},
      {"edge t = 1e-9", SurfacePoint::OnEdge(2, 3, 1e-9), K::kEdge},
      {"edge t = 0.5 (shared edge)", SurfacePoint::OnEdge(0, 2, 0.5), K::kEdge},
      {"edge t = 0.3 on the flipped face's boundary", SurfacePoint::OnEdge(3, 0, 0.3), K::kEdge},
      {"edge t = 1 - 1e-15", SurfacePoint::OnEdge(4, 5, 1 - 1e-15), K::kVertex},
      {"edge t = 1", SurfacePoint::OnEdge(4, 5, 1), K::kVertex},
      {"face point inside", SurfacePoint::InFace(0, 0.2, 0.3, 0.5), K::kFace},
      {"flipped face point inside", SurfacePoint::InFace(1, 0.2, 0.3, 0.5), K::kFace},
      {"face point 1e-13 from an edge", SurfacePoint::InFace(1, 1e-13, 0.4, 0.6 - 1e-13), K::kEdge},
      {"face point 1e-13 from a corner", SurfacePoint::InFace(1, 1 - 2e-13, 1e-13, 1e-13),
       K::kVertex},
      {"face point 1e-13 from the split corner", SurfacePoint::InFace(3, 1 - 2e-13, 1e-13, 1e-13),
       K::kVertex},
      {"face point 1e-9 from an edge", SurfacePoint::InFace(2, 1e-9, 0.5, 0.5 - 1e-9), K::kFace},
  };
}

class SurfacePointRulesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = BentFlippedBowtie();
    absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data_);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    mesh_ = std::make_unique<TriangleMesh>(std::move(*mesh));
    // The mesh is what the test says it is: a flipped face and a split vertex.
    ASSERT_TRUE(mesh_->FaceFlipped(1));
    ASSERT_FALSE(mesh_->FaceFlipped(0));
    ASSERT_GT(mesh_->vertex_count(), mesh_->file_vertex_count());
  }

  // The placements of `p`, ordered by vertex or face (an edge named in the other direction lists
  // its faces in another order).
  std::vector<ich::ResolvedSource> Resolve(const SurfacePoint& p) {
    SourceResolver resolver(*mesh_);
    absl::Status s = resolver.Add(p, 0);
    EXPECT_TRUE(s.ok()) << s;
    std::vector<ich::ResolvedSource> out = resolver.sources();
    std::sort(out.begin(), out.end(),
              [](const ich::ResolvedSource& a, const ich::ResolvedSource& b) {
                return std::make_pair(a.is_vertex, a.is_vertex ? a.vertex : a.face) <
                       std::make_pair(b.is_vertex, b.is_vertex ? b.vertex : b.face);
              });
    return out;
  }

  MeshData data_;
  std::unique_ptr<TriangleMesh> mesh_;
};

TEST_F(SurfacePointRulesTest, EveryPathAgreesOnSimplexAndPosition) {
  const SurfaceLocator locator(*mesh_);
  absl::StatusOr<DistanceField> field =
      ComputeDistanceField(*mesh_, {SurfacePoint::InFace(2, 0.3, 0.3, 0.4)});
  ASSERT_TRUE(field.ok()) << field.status();
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name + ": " + SurfacePointToString(c.point));
    ASSERT_TRUE(ValidateSurfacePoint(*mesh_, c.point).ok());
    const SurfacePoint canonical = CanonicalPoint(*mesh_, c.point);
    EXPECT_EQ(canonical.kind, c.expected) << SurfacePointToString(canonical);
    // Canonical is a fixed point, and moves the point by no more than the tolerance.
    EXPECT_TRUE(SameSimplex(CanonicalPoint(*mesh_, canonical), canonical, 0));
    const Vec3 where = PositionOf(data_, c.point);
    EXPECT_LE(Dist(PositionOf(data_, canonical), where), 4 * kSurfaceSnap);

    // Located from its position: the same simplex. (A point exactly at the tolerance may land on
    // either side of it once its position is rounded: there only the position must agree.)
    absl::StatusOr<LocatedPoint> located = locator.Locate(where);
    ASSERT_TRUE(located.ok()) << located.status();
    const bool at_the_tolerance = c.name.find("the tolerance itself") != std::string::npos;
    if (!at_the_tolerance) {
      EXPECT_TRUE(SameSimplex(located->point, canonical, 1e-12));
    }
    EXPECT_LE(Dist(PositionOf(data_, located->point), where), 4 * kSurfaceSnap);
    EXPECT_LE(located->distance, 1e-14);

    // Resolved: the point, its canonical form and its located form are placed alike (the first
    // two bit for bit), once per internal copy of a vertex and once per face of an edge.
    const std::vector<ich::ResolvedSource> given = Resolve(c.point);
    const std::vector<ich::ResolvedSource> canon = Resolve(canonical);
    const std::vector<ich::ResolvedSource> from_located = Resolve(located->point);
    ASSERT_EQ(given.size(), canon.size());
    ASSERT_EQ(given.size(), from_located.size());
    size_t expected_places = 1;
    if (canonical.kind == SurfacePoint::Kind::kVertex) {
      expected_places = canonical.vertex == 0 ? 2 : 1;  // the split vertex has two copies
    } else if (canonical.kind == SurfacePoint::Kind::kEdge) {
      expected_places = (canonical.edge_from == 0 && canonical.edge_to == 2) ||
                                (canonical.edge_from == 2 && canonical.edge_to == 0)
                            ? 2
                            : 1;
    }
    EXPECT_EQ(given.size(), expected_places);
    for (size_t i = 0; i < given.size(); ++i) {
      EXPECT_EQ(given[i].is_vertex, canon[i].is_vertex);
      EXPECT_EQ(given[i].is_vertex ? given[i].vertex : given[i].face,
                canon[i].is_vertex ? canon[i].vertex : canon[i].face);
      EXPECT_EQ(given[i].px, canon[i].px);
      EXPECT_EQ(given[i].py, canon[i].py);
      if (at_the_tolerance) continue;
      EXPECT_EQ(given[i].is_vertex, from_located[i].is_vertex);
      EXPECT_NEAR(given[i].px, from_located[i].px, 1e-12);
      EXPECT_NEAR(given[i].py, from_located[i].py, 1e-12);
    }

    // Placed for an estimate: the same value from the point and from its canonical form.
    absl::StatusOr<PointEstimate> a = EstimateDistanceAt(*mesh_, *field, c.point);
    absl::StatusOr<PointEstimate> b = EstimateDistanceAt(*mesh_, *field, canonical);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->distance, b->distance);
    EXPECT_EQ(a->source, b->source);

    // Solved from: the same field, bit for bit.
    absl::StatusOr<DistanceField> fa = ComputeDistanceField(*mesh_, {c.point});
    absl::StatusOr<DistanceField> fb = ComputeDistanceField(*mesh_, {canonical});
    ASSERT_TRUE(fa.ok() && fb.ok());
    EXPECT_EQ(fa->distance, fb->distance);
  }
}

// Where the old rules disagreed, and the rule now chosen. Before, the source resolver normalised
// and then snapped weights strictly below 1e-12; the locator snapped absolute weights <= 1e-12 and
// then normalised; the estimate at a point clamped and never snapped a face point (so a face point
// 1e-13 from an edge was estimated in its own face only, but solved as an edge point in both).
// Now every path normalises, then snaps weights <= kSurfaceSnap.
TEST_F(SurfacePointRulesTest, TheRuleWhereTheOldRulesDisagreed) {
  struct Disagreement {
    std::string name, old_rules;
    SurfacePoint point;
    SurfacePoint::Kind now;
  };
  const std::vector<Disagreement> table = {
      {"weight exactly 1e-12", "resolver: face point; locator: edge point",
       SurfacePoint::InFace(1, 1e-12, 0.5, 0.5 - 1e-12), SurfacePoint::Kind::kEdge},
      {"weight 1.0000000001e-12 with weights summing to 1 + 5e-10",
       "locator (snap before normalising): face point; resolver: edge point",
       SurfacePoint::InFace(1, 1.0000000001e-12, 0.5, 0.5 + 5e-10), SurfacePoint::Kind::kEdge},
      {"weight 1e-13",
       "estimate: a face point in face 0 only; resolver and locator: the edge point, in faces 0 "
       "and 1",
       SurfacePoint::InFace(0, 0.5, 1e-13, 0.5 - 1e-13), SurfacePoint::Kind::kEdge},
  };
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh_, {SurfacePoint::AtVertex(4)});
  ASSERT_TRUE(field.ok()) << field.status();
  for (const Disagreement& d : table) {
    SCOPED_TRACE(d.name + " (before: " + d.old_rules + ")");
    ASSERT_TRUE(ValidateSurfacePoint(*mesh_, d.point).ok());
    const SurfacePoint now = CanonicalPoint(*mesh_, d.point);
    EXPECT_EQ(now.kind, d.now) << SurfacePointToString(now);
    // The resolver places it as the edge point it now is: in every face of the edge.
    const std::vector<ich::ResolvedSource> placed = Resolve(d.point);
    const std::vector<ich::ResolvedSource> as_edge = Resolve(now);
    ASSERT_EQ(placed.size(), as_edge.size());
    // The estimate is the edge point's estimate, bit for bit.
    absl::StatusOr<PointEstimate> a = EstimateDistanceAt(*mesh_, *field, d.point);
    absl::StatusOr<PointEstimate> b = EstimateDistanceAt(*mesh_, *field, now);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->distance, b->distance);
  }
}

TEST(SurfacePointRules, FileCornersAndSwapCornerOrderAreInverse) {
  const MeshData data = BentFlippedBowtie();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(data);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  for (uint32_t f = 0; f < mesh->face_count(); ++f) {
    const std::array<uint32_t, 3> corners = mesh->FileCorners(f);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(corners[k], data.faces[3 * f + k]) << f << " " << k;
    std::array<double, 3> b{0.1, 0.2, 0.7};
    mesh->SwapCornerOrder(f, &b);
    mesh->SwapCornerOrder(f, &b);
    EXPECT_EQ(b, (std::array<double, 3>{0.1, 0.2, 0.7}));
  }
}

}  // namespace
}  // namespace geodex
