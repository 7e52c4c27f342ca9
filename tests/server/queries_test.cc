// geodexd's query methods beyond fields and paths: matrices, point distances, locate, isolines,
// Voronoi and Delaunay, each against core called directly, with results cut into many small
// stream messages (a tiny --stream_chunk_bytes) and reassembled.

#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <tuple>

#include "geodex/delaunay.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/isolines.h"
#include "geodex/locate.h"
#include "geodex/point_distance.h"
#include "geodex/voronoi.h"
#include "proto_convert.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using testing::BuildLocal;
using testing::GridOff;
using testing::In;
using testing::Upload;

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectSamePoint(const v1::PathPoint& got, const PathPoint& want) {
  EXPECT_TRUE(BitEqual(got.position().x(), want.position[0]));
  EXPECT_TRUE(BitEqual(got.position().y(), want.position[1]));
  EXPECT_TRUE(BitEqual(got.position().z(), want.position[2]));
  v1::SurfacePoint where;
  SurfacePointToProto(want.where, &where);
  EXPECT_EQ(got.where().SerializeAsString(), where.SerializeAsString());
}

void ExpectSamePolyline(const google::protobuf::RepeatedPtrField<v1::PathPoint>& got,
                        const std::vector<PathPoint>& want) {
  ASSERT_EQ(got.size(), static_cast<int>(want.size()));
  for (int i = 0; i < got.size(); ++i) ExpectSamePoint(got[i], want[i]);
}

// Reads every message of a server stream.
template <typename Response, typename Request, typename Method>
grpc::Status ReadAll(Method method, const Request& request, std::vector<Response>* out,
                     double timeout_seconds = 120) {
  grpc::ClientContext context;
  context.set_deadline(In(timeout_seconds));
  auto reader = method(&context, request);
  Response response;
  while (reader->Read(&response)) out->push_back(response);
  return reader->Finish();
}

// Concatenates the pieces of split items: pieces of one item are consecutive and all but the last
// have `continued` set. Returns the whole items in order.
template <typename Item>
std::vector<Item> JoinPieces(const std::vector<const Item*>& pieces, int* split_items) {
  std::vector<Item> items;
  bool open = false;
  for (const Item* piece : pieces) {
    if (open) {
      EXPECT_EQ(items.back().index(), piece->index());
      items.back().mutable_points()->MergeFrom(piece->points());
    } else {
      items.push_back(*piece);
    }
    if (piece->continued() && !open) ++*split_items;
    open = piece->continued();
    items.back().set_continued(false);
  }
  EXPECT_FALSE(open) << "the last piece says more follows";
  return items;
}

class QueriesTest : public testing::ServerFixture {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.limits.stream_chunk_bytes = 2000;  // many messages, items split across them
    StartServer(options);
    off_ = GridOff(24, 18, true);
    testing::UploadResult up = Upload(*stub_, off_, "hills");
    ASSERT_TRUE(up.status.ok()) << up.status.error_message();
    local_ = std::make_unique<TriangleMesh>(BuildLocal(off_));
  }

  std::vector<SurfacePoint> Sites() const {
    return {SurfacePoint::AtVertex(3), SurfacePoint::AtVertex(260),
            SurfacePoint::OnEdge(400, 401, 0.3), SurfacePoint::InFace(700, 0.2, 0.3, 0.5)};
  }
  template <typename Request>
  void AddSites(Request* request) const {
    for (const SurfacePoint& p : Sites()) SurfacePointToProto(p, request->add_sources());
  }
  DistanceField LocalField() const { return *ComputeDistanceField(*local_, Sites()); }

  std::string off_;
  std::unique_ptr<TriangleMesh> local_;
};

TEST_F(QueriesTest, SymmetricAndKNearestMatricesEqualCore) {
  // Rows run on the server's pool; answers are deterministic, so they equal core's bit for bit.
  std::vector<SurfacePoint> points = Sites();
  for (int v = 5; v < 475; v += 37) points.push_back(SurfacePoint::AtVertex(v));
  for (uint32_t k : {0u, 3u}) {
    v1::ComputeDistanceMatrixRequest request;
    request.set_mesh("meshes/hills");
    for (const SurfacePoint& p : points) {
      SurfacePointToProto(p, request.add_sources());
      SurfacePointToProto(p, request.add_targets());
    }
    request.set_k_nearest(k);
    std::vector<v1::ComputeDistanceMatrixResponse> messages;
    grpc::Status status = ReadAll<v1::ComputeDistanceMatrixResponse>(
        [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
        request, &messages);
    ASSERT_TRUE(status.ok()) << status.error_message();
    std::vector<double> values;
    for (const auto& m : messages) {
      values.insert(values.end(), m.values_f64().begin(), m.values_f64().end());
    }
    MatrixOptions options;
    options.k_nearest = k;
    const DistanceMatrix expected = *ComputeDistanceMatrix(*local_, points, points, options);
    ASSERT_EQ(values.size(), expected.values.size());
    const size_t n = points.size();
    size_t finite = 0;
    for (size_t i = 0; i < values.size(); ++i) {
      EXPECT_TRUE(BitEqual(values[i], expected.values[i])) << "k " << k << " entry " << i;
      if (std::isfinite(values[i])) ++finite;
      if (k == 0) {
        EXPECT_TRUE(BitEqual(values[i], values[(i % n) * n + i / n])) << i;  // symmetric
      }
    }
    EXPECT_EQ(finite, k == 0 ? n * n : n * k);
  }
}

// Batched pairs: grouped by source (one solve each), every path equal to a single FindShortestPath
// of that pair to 1e-12, unreachable pairs +inf without points.
TEST_F(QueriesTest, FindShortestPathsGroupsPairsBySource) {
  const std::vector<std::pair<SurfacePoint, SurfacePoint>> pairs = {
      {SurfacePoint::AtVertex(3), SurfacePoint::AtVertex(400)},
      {SurfacePoint::InFace(10, 0.6, 0.2, 0.2), SurfacePoint::AtVertex(17)},
      {SurfacePoint::AtVertex(3), SurfacePoint::OnEdge(100, 101, 0.9)},
      {SurfacePoint::AtVertex(3), SurfacePoint::InFace(200, 0.1, 0.3, 0.6)},
      {SurfacePoint::InFace(10, 0.6, 0.2, 0.2), SurfacePoint::AtVertex(474)},
  };
  v1::FindShortestPathsRequest request;
  request.set_mesh("meshes/hills");
  for (const auto& [from, to] : pairs) {
    v1::ShortestPathPair* pair = request.add_pairs();
    SurfacePointToProto(from, pair->mutable_from());
    SurfacePointToProto(to, pair->mutable_to());
  }
  request.set_want_stats(true);
  grpc::ClientContext context;
  context.set_deadline(In(120));
  v1::FindShortestPathsResponse response;
  grpc::Status status = stub_->FindShortestPaths(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.solves(), 2u);
  EXPECT_GT(response.stats().windows_created(), 0u);
  ASSERT_EQ(response.paths_size(), static_cast<int>(pairs.size()));
  for (size_t i = 0; i < pairs.size(); ++i) {
    absl::StatusOr<PathQueryResult> single =
        ComputeShortestPath(*local_, pairs[i].first, pairs[i].second);
    ASSERT_TRUE(single.ok());
    const v1::FindShortestPathResponse& got = response.paths(static_cast<int>(i));
    EXPECT_NEAR(got.distance(), single->distance, 1e-12 * std::max(1.0, single->distance)) << i;
    ASSERT_GE(got.points_size(), 2) << i;
    const PathPoint& end = single->path.points.back();
    EXPECT_NEAR(got.points(got.points_size() - 1).position().x(), end.position[0], 1e-9) << i;
    EXPECT_NEAR(got.points(got.points_size() - 1).position().y(), end.position[1], 1e-9) << i;
  }

  // An empty batch and a bad point name the field.
  v1::FindShortestPathsRequest bad;
  bad.set_mesh("meshes/hills");
  grpc::ClientContext c1;
  EXPECT_EQ(stub_->FindShortestPaths(&c1, bad, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  bad.add_pairs()->mutable_from()->set_vertex(0);
  bad.mutable_pairs(0)->mutable_to()->set_vertex(99999);
  grpc::ClientContext c2;
  grpc::Status s = stub_->FindShortestPaths(&c2, bad, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("pairs[0].to"), std::string::npos) << s.error_message();
}

TEST_F(QueriesTest, FindShortestPathsAnswersUnreachablePairsWithInf) {
  const std::string off =
      "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n5 5 0\n6 5 0\n5 6 0\n3 0 1 2\n3 3 4 5\n";
  testing::UploadResult up = Upload(*stub_, off);
  ASSERT_TRUE(up.status.ok());
  v1::FindShortestPathsRequest request;
  request.set_mesh(up.mesh.name());
  for (uint32_t to : {1u, 4u}) {
    v1::ShortestPathPair* pair = request.add_pairs();
    pair->mutable_from()->set_vertex(0);
    pair->mutable_to()->set_vertex(to);
  }
  grpc::ClientContext context;
  v1::FindShortestPathsResponse response;
  ASSERT_TRUE(stub_->FindShortestPaths(&context, request, &response).ok());
  ASSERT_EQ(response.paths_size(), 2);
  EXPECT_EQ(response.paths(0).distance(), 1.0);
  EXPECT_TRUE(std::isinf(response.paths(1).distance()));
  EXPECT_EQ(response.paths(1).points_size(), 0);
}

TEST_F(QueriesTest, DistanceMatrixEqualsCoreBitForBit) {
  std::vector<SurfacePoint> sources = Sites();
  sources.push_back(SurfacePoint::AtVertex(3));  // repeated row
  std::vector<SurfacePoint> targets = {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(474),
                                       SurfacePoint::InFace(10, 0.6, 0.2, 0.2),
                                       SurfacePoint::OnEdge(100, 101, 0.9)};
  for (int v = 0; v < 475; v += 7) targets.push_back(SurfacePoint::AtVertex(v));
  v1::ComputeDistanceMatrixRequest request;
  request.set_mesh("meshes/hills");
  for (const SurfacePoint& p : sources) SurfacePointToProto(p, request.add_sources());
  for (const SurfacePoint& p : targets) SurfacePointToProto(p, request.add_targets());
  request.set_want_stats(true);
  std::vector<v1::ComputeDistanceMatrixResponse> messages;
  grpc::Status status = ReadAll<v1::ComputeDistanceMatrixResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
      request, &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GT(messages.size(), 1u);

  DistanceMatrix expected = *ComputeDistanceMatrix(*local_, sources, targets);
  std::vector<double> values;
  for (const auto& m : messages) {
    EXPECT_EQ(m.rows(), sources.size());
    EXPECT_EQ(m.cols(), targets.size());
    EXPECT_EQ(m.offset(), values.size());
    values.insert(values.end(), m.values_f64().begin(), m.values_f64().end());
  }
  ASSERT_EQ(values.size(), expected.values.size());
  for (size_t i = 0; i < values.size(); ++i)
    EXPECT_TRUE(BitEqual(values[i], expected.values[i])) << i;
  for (size_t j = 0; j < targets.size(); ++j) {
    EXPECT_TRUE(BitEqual(values[4 * targets.size() + j], values[j]));  // repeated source row
  }
  EXPECT_TRUE(messages.back().has_stats());
  EXPECT_GT(messages.back().stats().windows_created(), 0u);

  request.set_value_type(v1::VALUE_TYPE_FLOAT32);
  messages.clear();
  status = ReadAll<v1::ComputeDistanceMatrixResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
      request, &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  size_t k = 0;
  for (const auto& m : messages) {
    for (float v : m.values_f32()) EXPECT_EQ(v, static_cast<float>(expected.values[k++]));
  }
  EXPECT_EQ(k, expected.values.size());
}

TEST_F(QueriesTest, EstimateAndExactDistancesEqualCore) {
  std::vector<SurfacePoint> points = {
      SurfacePoint::AtVertex(5), SurfacePoint::InFace(11, 0.1, 0.1, 0.8),
      SurfacePoint::OnEdge(200, 201, 0.5), SurfacePoint::InFace(850, 0.3, 0.3, 0.4)};
  v1::EstimateDistancesRequest request;
  request.set_mesh("meshes/hills");
  AddSites(&request);
  for (const SurfacePoint& p : points) SurfacePointToProto(p, request.add_points());
  request.set_mode(v1::POINT_DISTANCE_MODE_BOTH);
  request.set_want_stats(true);
  grpc::ClientContext context;
  context.set_deadline(In(60));
  v1::EstimateDistancesResponse response;
  grpc::Status status = stub_->EstimateDistances(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();

  DistanceField field = LocalField();
  auto exact = *ComputeExactDistancesAt(*local_, Sites(), points);
  ASSERT_EQ(response.estimates_size(), 4);
  ASSERT_EQ(response.exact_size(), 4);
  for (int i = 0; i < 4; ++i) {
    PointEstimate e = *EstimateDistanceAt(*local_, field, points[i]);
    EXPECT_TRUE(BitEqual(response.estimates(i), e.distance));
    EXPECT_EQ(response.estimate_labels(i), e.source);
    EXPECT_TRUE(BitEqual(response.exact(i), exact[i].first));
    EXPECT_EQ(response.exact_labels(i), exact[i].second);
  }
  EXPECT_TRUE(BitEqual(response.estimates(0), response.exact(0)));  // exact at a vertex
  EXPECT_GT(response.estimate_stats().windows_created(), 0u);
  EXPECT_GT(response.exact_stats().windows_created(), 0u);

  // Each mode fills only its arrays; unspecified means the estimate.
  for (auto [mode, estimates, exacts] : {std::tuple{v1::POINT_DISTANCE_MODE_EXACT, 0, 4},
                                         std::tuple{v1::POINT_DISTANCE_MODE_UNSPECIFIED, 4, 0}}) {
    request.set_mode(mode);
    grpc::ClientContext c;
    c.set_deadline(In(60));
    v1::EstimateDistancesResponse r;
    ASSERT_TRUE(stub_->EstimateDistances(&c, request, &r).ok());
    EXPECT_EQ(r.estimates_size(), estimates);
    EXPECT_EQ(r.exact_size(), exacts);
  }
}

// want_directions: each point's direction, bit-equal to core's; refused (naming the field) when
// the mode has no exact solve.
TEST_F(QueriesTest, DirectionsAtPointsEqualCoreAndNeedTheExactMode) {
  PointQuery query;
  query.sources = Sites();
  query.points = {SurfacePoint::AtVertex(5), SurfacePoint::InFace(11, 0.1, 0.1, 0.8),
                  SurfacePoint::OnEdge(200, 201, 0.5)};
  query.directions = true;
  v1::EstimateDistancesRequest request;
  request.set_mesh("meshes/hills");
  api::PointQueryToProto(query, &request);
  request.set_mode(v1::POINT_DISTANCE_MODE_EXACT);
  grpc::ClientContext context;
  context.set_deadline(In(60));
  v1::EstimateDistancesResponse response;
  grpc::Status status = stub_->EstimateDistances(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  absl::StatusOr<PointValues> local = ComputePointValues(*local_, query);
  ASSERT_TRUE(local.ok()) << local.status();
  const PointValues remote = api::PointValuesFromProto(response);
  ASSERT_EQ(remote.direction.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(BitEqual(remote.direction[i][c], local->direction[i][c]));
    }
    EXPECT_NEAR(std::hypot(remote.direction[i][0], remote.direction[i][1], remote.direction[i][2]),
                1, 1e-12);
  }
  request.set_mode(v1::POINT_DISTANCE_MODE_ESTIMATE);
  grpc::ClientContext c;
  c.set_deadline(In(60));
  status = stub_->EstimateDistances(&c, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(testing::BadField(status), "want_directions");
}

TEST_F(QueriesTest, LocatePointsEqualsCore) {
  SurfaceLocator locator(*local_);
  v1::LocatePointsRequest request;
  request.set_mesh("meshes/hills");
  std::vector<std::array<double, 3>> queries = {
      {0, 0, 0}, {3.3, 7.1, 2}, {12, 9, -4}, {24, 18, 0.3}, {-5, 40, 1}};
  for (const auto& q : queries) {
    v1::Position* p = request.add_positions();
    p->set_x(q[0]);
    p->set_y(q[1]);
    p->set_z(q[2]);
  }
  grpc::ClientContext context;
  context.set_deadline(In(60));
  v1::LocatePointsResponse response;
  grpc::Status status = stub_->LocatePoints(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.points_size(), static_cast<int>(queries.size()));
  for (size_t i = 0; i < queries.size(); ++i) {
    LocatedPoint want = *locator.Locate(queries[i]);
    const v1::LocatedPoint& got = response.points(static_cast<int>(i));
    v1::SurfacePoint where;
    SurfacePointToProto(want.point, &where);
    EXPECT_EQ(got.point().SerializeAsString(), where.SerializeAsString());
    EXPECT_TRUE(BitEqual(got.position().x(), want.position[0]));
    EXPECT_TRUE(BitEqual(got.distance(), want.distance));
  }
  EXPECT_EQ(response.points(0).point().point_case(), v1::SurfacePoint::kVertex);

  // max_snap: a limit between the nearest and the farthest query refuses exactly the position
  // that is farther, naming it; a limit above all of them changes nothing; 0 is refused.
  double nearest = response.points(0).distance(), farthest = nearest;
  for (int i = 0; i < response.points_size(); ++i) {
    nearest = std::min(nearest, response.points(i).distance());
    farthest = std::max(farthest, response.points(i).distance());
  }
  ASSERT_LT(nearest, farthest);
  for (const double limit : {0.5 * (nearest + farthest), 2 * farthest, 0.0}) {
    v1::LocatePointsRequest limited = request;
    limited.set_max_snap(limit);
    grpc::ClientContext c;
    c.set_deadline(In(60));
    v1::LocatePointsResponse r;
    grpc::Status s = stub_->LocatePoints(&c, limited, &r);
    if (limit > farthest) {
      ASSERT_TRUE(s.ok()) << s.error_message();
      EXPECT_EQ(r.SerializeAsString(), response.SerializeAsString());
    } else {
      EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
      const std::string field = limit == 0 ? "max_snap" : "positions[";
      EXPECT_NE(s.error_message().find(field), std::string::npos) << s.error_message();
      if (limit > 0) {  // the first position farther than the limit is named
        int first = 0;
        while (response.points(first).distance() <= limit) ++first;
        EXPECT_NE(s.error_message().find("positions[" + std::to_string(first) + "]: "),
                  std::string::npos)
            << s.error_message();
        EXPECT_NE(s.error_message().find("maximum snap distance"), std::string::npos);
      }
    }
  }
}

// max_snap and snap_distances on every request that takes points (the proto's "Snapping"): a
// position `d` off the surface is refused below d naming its field, passes above it and unset, and
// every answer reports d for it (bit for bit LocatePoints' distance) and 0 for a vertex.
TEST_F(QueriesTest, MaxSnapOnEveryRequestThatTakesPoints) {
  const std::array<double, 3> off_surface = {7.3, 5.2, 4.0};
  absl::StatusOr<LocatedPoint> located = SurfaceLocator(*local_).Locate(off_surface);
  ASSERT_TRUE(located.ok());
  const double d = located->distance;
  ASSERT_GT(d, 0.5);
  v1::SurfacePoint vertex, far;
  vertex.set_vertex(3);
  far.mutable_position()->set_x(off_surface[0]);
  far.mutable_position()->set_y(off_surface[1]);
  far.mutable_position()->set_z(off_surface[2]);

  // Each case: fills a request (vertex first, then the far position), runs it with `max_snap`
  // (< 0: unset) and returns its status and the answer's snap distances.
  struct Answer {
    Answer(grpc::Status s) : status(std::move(s)) {}  // NOLINT: implicit, from a call's status
    grpc::Status status;
    std::vector<double> snaps;
  };
  using Run = std::function<Answer(double max_snap)>;
  std::vector<std::tuple<std::string, std::string, Run>> cases;

  {
    v1::ComputeDistanceFieldRequest r;
    r.set_mesh("meshes/hills");
    *r.add_sources() = vertex;
    *r.add_sources() = far;
    cases.emplace_back("field", "sources[1].position", [=, this](double max_snap) {
      auto q = r;
      if (max_snap >= 0) q.set_max_snap(max_snap);
      std::vector<v1::ComputeDistanceFieldResponse> m;
      Answer a{ReadAll<v1::ComputeDistanceFieldResponse>(
          [&](grpc::ClientContext* c, const auto& x) { return stub_->ComputeDistanceField(c, x); },
          q, &m)};
      if (a.status.ok()) a.snaps.assign(m[0].snap_distances().begin(), m[0].snap_distances().end());
      return a;
    });
  }
  {
    v1::FindShortestPathRequest r;
    r.set_mesh("meshes/hills");
    *r.mutable_from() = vertex;
    *r.mutable_to() = far;
    cases.emplace_back("path", "to.position", [=, this](double max_snap) {
      auto q = r;
      if (max_snap >= 0) q.set_max_snap(max_snap);
      grpc::ClientContext c;
      c.set_deadline(In(120));
      v1::FindShortestPathResponse response;
      Answer a{stub_->FindShortestPath(&c, q, &response)};
      a.snaps.assign(response.snap_distances().begin(), response.snap_distances().end());
      return a;
    });
  }
  {
    v1::FindShortestPathsRequest r;
    r.set_mesh("meshes/hills");
    v1::ShortestPathPair* pair = r.add_pairs();
    *pair->mutable_from() = vertex;
    *pair->mutable_to() = far;
    cases.emplace_back("paths", "pairs[0].to.position", [=, this](double max_snap) {
      auto q = r;
      if (max_snap >= 0) q.set_max_snap(max_snap);
      grpc::ClientContext c;
      c.set_deadline(In(120));
      v1::FindShortestPathsResponse response;
      Answer a{stub_->FindShortestPaths(&c, q, &response)};
      if (a.status.ok()) {
        a.snaps.assign(response.paths(0).snap_distances().begin(),
                       response.paths(0).snap_distances().end());
      }
      return a;
    });
  }
  {
    v1::ComputeDistanceMatrixRequest r;
    r.set_mesh("meshes/hills");
    *r.add_sources() = vertex;
    *r.add_targets() = far;
    cases.emplace_back("matrix", "targets[0].position", [=, this](double max_snap) {
      auto q = r;
      if (max_snap >= 0) q.set_max_snap(max_snap);
      std::vector<v1::ComputeDistanceMatrixResponse> m;
      Answer a{ReadAll<v1::ComputeDistanceMatrixResponse>(
          [&](grpc::ClientContext* c, const auto& x) { return stub_->ComputeDistanceMatrix(c, x); },
          q, &m)};
      if (a.status.ok()) a.snaps.assign(m[0].snap_distances().begin(), m[0].snap_distances().end());
      return a;
    });
  }
  {
    v1::EstimateDistancesRequest r;
    r.set_mesh("meshes/hills");
    *r.add_sources() = vertex;
    *r.add_points() = far;
    r.set_mode(v1::POINT_DISTANCE_MODE_BOTH);
    cases.emplace_back("estimate", "points[0].position", [=, this](double max_snap) {
      auto q = r;
      if (max_snap >= 0) q.set_max_snap(max_snap);
      grpc::ClientContext c;
      c.set_deadline(In(120));
      v1::EstimateDistancesResponse response;
      Answer a{stub_->EstimateDistances(&c, q, &response)};
      a.snaps.assign(response.snap_distances().begin(), response.snap_distances().end());
      return a;
    });
  }
  auto geometry = [&](const std::string& name, auto request, auto method, auto response_type) {
    request.set_mesh("meshes/hills");
    *request.add_sources() = vertex;
    *request.add_sources() = far;
    using Request = decltype(request);
    cases.emplace_back(name, "sources[1].position", [=, this](double max_snap) {
      Request q = request;
      if (max_snap >= 0) q.set_max_snap(max_snap);
      using Response = decltype(response_type);
      std::vector<Response> m;
      Answer a{ReadAll<Response>(
          [&](grpc::ClientContext* c, const Request& x) { return method(stub_.get(), c, x); }, q,
          &m)};
      if (a.status.ok()) a.snaps.assign(m[0].snap_distances().begin(), m[0].snap_distances().end());
      return a;
    });
  };
  {
    v1::ComputeIsolinesRequest r;
    r.set_count(4);
    geometry(
        "isolines", r,
        [](v1::Geodex::Stub* s, grpc::ClientContext* c, const auto& x) {
          return s->ComputeIsolines(c, x);
        },
        v1::ComputeIsolinesResponse());
  }
  geometry(
      "voronoi", v1::ComputeVoronoiRequest(),
      [](v1::Geodex::Stub* s, grpc::ClientContext* c, const auto& x) {
        return s->ComputeVoronoi(c, x);
      },
      v1::ComputeVoronoiResponse());
  geometry(
      "delaunay", v1::ComputeDelaunayRequest(),
      [](v1::Geodex::Stub* s, grpc::ClientContext* c, const auto& x) {
        return s->ComputeDelaunay(c, x);
      },
      v1::ComputeDelaunayResponse());

  for (const auto& [name, field, run] : cases) {
    SCOPED_TRACE(name);
    for (const double max_snap : {-1.0, 2 * d}) {  // unset, above
      Answer a = run(max_snap);
      ASSERT_TRUE(a.status.ok()) << a.status.error_message();
      ASSERT_EQ(a.snaps.size(), 2u);
      EXPECT_EQ(a.snaps[0], 0.0);
      EXPECT_TRUE(BitEqual(a.snaps[1], d)) << a.snaps[1] << " vs " << d;
    }
    Answer below = run(0.5 * d);
    EXPECT_EQ(below.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(below.status.error_message().find(field + ": "), std::string::npos)
        << below.status.error_message();
    EXPECT_NE(below.status.error_message().find("maximum snap distance"), std::string::npos);
    Answer zero = run(0.0);
    EXPECT_EQ(zero.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(zero.status.error_message().find("max_snap"), std::string::npos);
  }
  EXPECT_EQ(cases.size(), 8u);  // ExportGis: in terrain_service_test (it needs a DEM)
}

TEST_F(QueriesTest, IsolinesEqualCoreAcrossManyMessages) {
  v1::ComputeIsolinesRequest request;
  request.set_mesh("meshes/hills");
  AddSites(&request);
  request.set_count(8);
  request.set_want_stats(true);
  std::vector<v1::ComputeIsolinesResponse> messages;
  grpc::Status status = ReadAll<v1::ComputeIsolinesResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeIsolines(c, r); }, request,
      &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GT(messages.size(), 2u);

  IsolineOptions options;
  options.count = 8;
  Isolines expected = *ExtractIsolines(*local_, LocalField(), options);
  ASSERT_EQ(messages[0].levels_size(), static_cast<int>(expected.levels.size()));
  for (size_t i = 0; i < expected.levels.size(); ++i) {
    EXPECT_TRUE(BitEqual(messages[0].levels(static_cast<int>(i)), expected.levels[i]));
  }
  std::vector<const v1::Isoline*> pieces;
  for (const auto& m : messages) {
    for (const auto& piece : m.isolines()) pieces.push_back(&piece);
    if (&m != &messages[0]) {
      EXPECT_EQ(m.levels_size(), 0);
    }
  }
  int split = 0;
  std::vector<v1::Isoline> lines = JoinPieces(pieces, &split);
  EXPECT_GT(split, 0) << "no isoline was long enough to be split; the test proves less";
  ASSERT_EQ(lines.size(), expected.polylines.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(lines[i].index(), i);
    EXPECT_TRUE(BitEqual(lines[i].level(), expected.polylines[i].level));
    EXPECT_EQ(lines[i].closed(), expected.polylines[i].closed);
    ExpectSamePolyline(lines[i].points(), expected.polylines[i].points);
  }
  EXPECT_TRUE(messages.back().has_stats());
}

TEST_F(QueriesTest, VoronoiEqualsCoreAcrossManyMessages) {
  v1::ComputeVoronoiRequest request;
  request.set_mesh("meshes/hills");
  AddSites(&request);
  std::vector<v1::ComputeVoronoiResponse> messages;
  grpc::Status status = ReadAll<v1::ComputeVoronoiResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeVoronoi(c, r); }, request,
      &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GT(messages.size(), 2u);
  VoronoiDiagram expected = *BuildVoronoi(*local_, LocalField());

  EXPECT_TRUE(BitEqual(messages[0].total_area(), expected.total_area));
  EXPECT_EQ(messages[0].junction_faces(), expected.junction_faces);
  ASSERT_EQ(messages[0].adjacency_size(), static_cast<int>(expected.adjacency.size()));
  for (size_t i = 0; i < expected.adjacency.size(); ++i) {
    EXPECT_EQ(messages[0].adjacency(static_cast<int>(i)).a(), expected.adjacency[i][0]);
    EXPECT_EQ(messages[0].adjacency(static_cast<int>(i)).b(), expected.adjacency[i][1]);
  }
  EXPECT_EQ(messages[0].resolved_sources_size(), 4);

  // Cells: join pieces by `continued`.
  std::vector<v1::VoronoiCell> cells;
  bool open = false;
  int split_cells = 0;
  std::vector<const v1::VoronoiBoundary*> boundary_pieces;
  for (const auto& m : messages) {
    for (const auto& piece : m.cells()) {
      if (open) {
        EXPECT_EQ(cells.back().site(), piece.site());
        cells.back().mutable_whole_faces()->MergeFrom(piece.whole_faces());
        cells.back().mutable_fragments()->MergeFrom(piece.fragments());
      } else {
        cells.push_back(piece);
      }
      split_cells += piece.continued() && !open;
      open = piece.continued();
    }
    for (const auto& piece : m.boundaries()) boundary_pieces.push_back(&piece);
  }
  EXPECT_FALSE(open);
  EXPECT_GT(split_cells, 0);
  ASSERT_EQ(cells.size(), expected.cells.size());
  for (size_t c = 0; c < cells.size(); ++c) {
    const VoronoiCell& want = expected.cells[c];
    EXPECT_EQ(cells[c].site(), want.site);
    EXPECT_TRUE(BitEqual(cells[c].area(), want.area));
    EXPECT_EQ(std::vector<uint32_t>(cells[c].whole_faces().begin(), cells[c].whole_faces().end()),
              want.whole_faces);
    ASSERT_EQ(cells[c].fragments_size(), static_cast<int>(want.fragments.size()));
    for (size_t f = 0; f < want.fragments.size(); ++f) {
      const v1::VoronoiFragment& got = cells[c].fragments(static_cast<int>(f));
      EXPECT_EQ(got.face(), want.fragments[f].face);
      EXPECT_TRUE(BitEqual(got.area(), want.fragments[f].area));
      ExpectSamePolyline(got.polygon(), want.fragments[f].polygon);
    }
  }
  int split = 0;
  std::vector<v1::VoronoiBoundary> boundaries = JoinPieces(boundary_pieces, &split);
  ASSERT_EQ(boundaries.size(), expected.boundaries.size());
  for (size_t i = 0; i < boundaries.size(); ++i) {
    EXPECT_EQ(boundaries[i].site_a(), expected.boundaries[i].site_a);
    EXPECT_EQ(boundaries[i].site_b(), expected.boundaries[i].site_b);
    EXPECT_EQ(boundaries[i].closed(), expected.boundaries[i].closed);
    ExpectSamePolyline(boundaries[i].points(), expected.boundaries[i].points);
  }

  // omit_cell_faces: sites and areas only.
  request.set_omit_cell_faces(true);
  messages.clear();
  ASSERT_TRUE(
      ReadAll<v1::ComputeVoronoiResponse>(
          [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeVoronoi(c, r); },
          request, &messages)
          .ok());
  int cell_count = 0;
  for (const auto& m : messages) {
    for (const auto& cell : m.cells()) {
      EXPECT_EQ(cell.whole_faces_size() + cell.fragments_size(), 0);
      EXPECT_FALSE(cell.continued());
      ++cell_count;
    }
  }
  EXPECT_EQ(cell_count, static_cast<int>(expected.cells.size()));
}

TEST_F(QueriesTest, DelaunayEqualsCoreAcrossManyMessages) {
  v1::ComputeDelaunayRequest request;
  request.set_mesh("meshes/hills");
  AddSites(&request);
  request.set_want_stats(true);
  std::vector<v1::ComputeDelaunayResponse> messages;
  grpc::Status status = ReadAll<v1::ComputeDelaunayResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDelaunay(c, r); }, request,
      &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  DelaunayTriangulation expected = *BuildDelaunay(*local_, LocalField());
  ASSERT_FALSE(expected.edges.empty());

  std::vector<const v1::DelaunayEdge*> kept, removed;
  std::vector<v1::SiteTriple> triangles;
  int xl = 0;
  for (const auto& m : messages) {
    for (const auto& e : m.edges()) kept.push_back(&e);
    for (const auto& e : m.removed_edges()) removed.push_back(&e);
    triangles.insert(triangles.end(), m.triangles().begin(), m.triangles().end());
    xl += m.xl_edges_size();
  }
  int split = 0;
  std::vector<v1::DelaunayEdge> edges = JoinPieces(kept, &split);
  std::vector<v1::DelaunayEdge> removed_edges = JoinPieces(removed, &split);
  ASSERT_EQ(edges.size(), expected.edges.size());
  ASSERT_EQ(removed_edges.size(), expected.removed_edges.size());
  for (size_t i = 0; i < edges.size(); ++i) {
    const DelaunayEdge& want = expected.edges[i];
    EXPECT_EQ(edges[i].site_a(), want.site_a);
    EXPECT_EQ(edges[i].site_b(), want.site_b);
    EXPECT_EQ(edges[i].vertex_a(), want.vertex_a);
    EXPECT_EQ(edges[i].vertex_b(), want.vertex_b);
    EXPECT_EQ(edges[i].edge_start(), want.edge_start);
    EXPECT_TRUE(BitEqual(edges[i].length(), want.length));
    ExpectSamePolyline(edges[i].points(), want.points);
  }
  ASSERT_EQ(triangles.size(), expected.triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    EXPECT_EQ(triangles[i].a(), expected.triangles[i][0]);
    EXPECT_EQ(triangles[i].c(), expected.triangles[i][2]);
  }
  EXPECT_EQ(xl, static_cast<int>(expected.xl_edges.size()));
  EXPECT_TRUE(messages.back().has_stats());
}

// Each new method: unknown mesh, a bad point, and its own limits, with the field or flag named.
TEST_F(QueriesTest, BadInputAndLimitsNameTheFieldOrFlag) {
  auto expect = [](const grpc::Status& s, grpc::StatusCode code, const std::string& needle) {
    EXPECT_EQ(s.error_code(), code) << s.error_message();
    EXPECT_NE(s.error_message().find(needle), std::string::npos) << s.error_message();
  };
  auto matrix = [&](const v1::ComputeDistanceMatrixRequest& r) {
    std::vector<v1::ComputeDistanceMatrixResponse> m;
    return ReadAll<v1::ComputeDistanceMatrixResponse>(
        [&](grpc::ClientContext* c, const auto& q) { return stub_->ComputeDistanceMatrix(c, q); },
        r, &m, 30);
  };
  auto isolines = [&](const v1::ComputeIsolinesRequest& r) {
    std::vector<v1::ComputeIsolinesResponse> m;
    return ReadAll<v1::ComputeIsolinesResponse>(
        [&](grpc::ClientContext* c, const auto& q) { return stub_->ComputeIsolines(c, q); }, r, &m,
        30);
  };
  auto voronoi = [&](const v1::ComputeVoronoiRequest& r) {
    std::vector<v1::ComputeVoronoiResponse> m;
    return ReadAll<v1::ComputeVoronoiResponse>(
        [&](grpc::ClientContext* c, const auto& q) { return stub_->ComputeVoronoi(c, q); }, r, &m,
        30);
  };
  auto delaunay = [&](const v1::ComputeDelaunayRequest& r) {
    std::vector<v1::ComputeDelaunayResponse> m;
    return ReadAll<v1::ComputeDelaunayResponse>(
        [&](grpc::ClientContext* c, const auto& q) { return stub_->ComputeDelaunay(c, q); }, r, &m,
        30);
  };
  auto estimate = [&](const v1::EstimateDistancesRequest& r) {
    grpc::ClientContext c;
    c.set_deadline(In(30));
    v1::EstimateDistancesResponse out;
    return stub_->EstimateDistances(&c, r, &out);
  };
  auto locate = [&](const v1::LocatePointsRequest& r) {
    grpc::ClientContext c;
    c.set_deadline(In(30));
    v1::LocatePointsResponse out;
    return stub_->LocatePoints(&c, r, &out);
  };

  // Matrix.
  v1::ComputeDistanceMatrixRequest m;
  m.set_mesh("meshes/nope");
  m.add_sources()->set_vertex(0);
  m.add_targets()->set_vertex(1);
  expect(matrix(m), grpc::StatusCode::NOT_FOUND, "mesh");
  m.set_mesh("meshes/hills");
  m.add_targets()->set_vertex(475);
  expect(matrix(m), grpc::StatusCode::INVALID_ARGUMENT, "targets[1].vertex");
  m.clear_targets();
  expect(matrix(m), grpc::StatusCode::INVALID_ARGUMENT, "targets");
  m.add_targets()->mutable_face()->set_face(5);  // barycentrics 0, 0, 0
  expect(matrix(m), grpc::StatusCode::INVALID_ARGUMENT, "targets[0].face");

  // Point distances.
  v1::EstimateDistancesRequest e;
  e.set_mesh("meshes/hills");
  e.add_sources()->set_vertex(0);
  expect(estimate(e), grpc::StatusCode::INVALID_ARGUMENT, "points");
  e.add_points()->set_vertex(1);
  e.set_mode(static_cast<v1::PointDistanceMode>(42));
  expect(estimate(e), grpc::StatusCode::INVALID_ARGUMENT, "mode");
  e.set_mode(v1::POINT_DISTANCE_MODE_BOTH);
  e.mutable_options()->set_lambda(-1);
  expect(estimate(e), grpc::StatusCode::INVALID_ARGUMENT, "options.lambda");

  // Locate.
  v1::LocatePointsRequest l;
  l.set_mesh("meshes/hills");
  expect(locate(l), grpc::StatusCode::INVALID_ARGUMENT, "positions");
  l.add_positions()->set_x(1);
  l.add_positions()->set_x(std::nan(""));
  expect(locate(l), grpc::StatusCode::INVALID_ARGUMENT, "positions[1]");

  // Isolines.
  v1::ComputeIsolinesRequest i;
  i.set_mesh("meshes/hills");
  i.add_sources()->set_vertex(0);
  expect(isolines(i), grpc::StatusCode::INVALID_ARGUMENT, "count");
  i.add_levels(1.0);
  i.add_levels(INFINITY);
  expect(isolines(i), grpc::StatusCode::INVALID_ARGUMENT, "levels[1]");
  i.clear_levels();
  i.set_count(5000);
  expect(isolines(i), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max_levels");
  for (int k = 0; k < 1001; ++k) i.add_levels(k);
  expect(isolines(i), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max_levels");

  // Voronoi and Delaunay.
  v1::ComputeVoronoiRequest vr;
  vr.set_mesh("meshes/hills");
  expect(voronoi(vr), grpc::StatusCode::INVALID_ARGUMENT, "sources");
  vr.add_sources()->mutable_edge()->set_t(2);
  expect(voronoi(vr), grpc::StatusCode::INVALID_ARGUMENT, "sources[0].edge");
  v1::ComputeDelaunayRequest dr;
  dr.set_mesh("hills");
  dr.add_sources()->set_vertex(0);
  expect(delaunay(dr), grpc::StatusCode::INVALID_ARGUMENT, "mesh");
}

// Matrix rows stream as they finish (issue 19): with one compute worker the rows are solved one
// after another, and the first message holds exactly the first row, sent before the second row is
// solved; the reassembled matrix still equals core bit for bit, stats in the last message only.
// A call cancelled after its first rows stops the rest.
class MatrixStreamingTest : public testing::ServerFixture {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.pool_threads = 1;
    options.quick_threads = 0;
    StartServer(options);
  }
};

TEST_F(MatrixStreamingTest, RowsArriveAsTheyFinishInOrder) {
  const std::string off = GridOff(24, 18, true);
  ASSERT_TRUE(Upload(*stub_, off, "hills").status.ok());
  const TriangleMesh local = BuildLocal(off);
  std::vector<SurfacePoint> sources, targets;
  for (uint32_t k = 0; k < 8; ++k) sources.push_back(SurfacePoint::AtVertex(5 + 53 * k));
  for (uint32_t k = 0; k < 5; ++k) targets.push_back(SurfacePoint::AtVertex(11 + 71 * k));
  v1::ComputeDistanceMatrixRequest request;
  request.set_mesh("meshes/hills");
  request.set_want_stats(true);
  for (const SurfacePoint& p : sources) SurfacePointToProto(p, request.add_sources());
  for (const SurfacePoint& p : targets) SurfacePointToProto(p, request.add_targets());
  std::vector<v1::ComputeDistanceMatrixResponse> messages;
  grpc::Status status = ReadAll<v1::ComputeDistanceMatrixResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
      request, &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(messages.size(), 2u);
  EXPECT_EQ(messages[0].offset(), 0u);
  EXPECT_EQ(messages[0].values_f64_size(), 5) << "the first message is the first row alone";
  const DistanceMatrix expected = *ComputeDistanceMatrix(local, sources, targets);
  std::vector<double> got;
  for (size_t i = 0; i < messages.size(); ++i) {
    EXPECT_EQ(messages[i].offset(), got.size());
    EXPECT_EQ(messages[i].has_stats(), i + 1 == messages.size()) << "message " << i;
    got.insert(got.end(), messages[i].values_f64().begin(), messages[i].values_f64().end());
  }
  ASSERT_EQ(got.size(), expected.values.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(BitEqual(got[i], expected.values[i])) << i;
  EXPECT_EQ(messages.back().stats().windows_processed(), expected.stats.windows_processed);
  // Progress never goes back and ends at 1.
  for (size_t i = 1; i < messages.size(); ++i) {
    EXPECT_GE(messages[i].progress(), messages[i - 1].progress()) << i;
  }
  EXPECT_EQ(messages.back().progress(), 1.0);
}

TEST_F(MatrixStreamingTest, CancellingAfterTheFirstRowsStopsTheRest) {
  ASSERT_TRUE(Upload(*stub_, GridOff(120, 120, true), "big").status.ok());
  v1::ComputeDistanceMatrixRequest request;
  request.set_mesh("meshes/big");
  for (uint32_t k = 0; k < 40; ++k) {  // spread rows: each about a full field
    request.add_sources()->set_vertex((k * 7919) % 14641);
    request.add_targets()->set_vertex((k * 104729 + 13) % 14641);
  }
  grpc::ClientContext context;
  context.set_deadline(In(120));
  auto reader = stub_->ComputeDistanceMatrix(&context, request);
  v1::ComputeDistanceMatrixResponse first;
  ASSERT_TRUE(reader->Read(&first));
  EXPECT_LT(static_cast<size_t>(first.values_f64_size()), 40u * 40u);
  context.TryCancel();
  v1::ComputeDistanceMatrixResponse more;
  while (reader->Read(&more)) {
  }
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
  // The only worker is free again: a small matrix on it answers.
  v1::ComputeDistanceMatrixRequest small;
  small.set_mesh("meshes/big");
  small.add_sources()->set_vertex(0);
  small.add_targets()->set_vertex(1);
  std::vector<v1::ComputeDistanceMatrixResponse> messages;
  grpc::Status status = ReadAll<v1::ComputeDistanceMatrixResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
      small, &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_FALSE(messages.empty());
  ASSERT_EQ(messages.back().values_f64_size(), 1);
  EXPECT_GT(messages.back().values_f64(0), 0);
}

class QueryLimitsTest : public testing::ServerFixture {};

TEST_F(QueryLimitsTest, TargetsOutputAndResponseLimits) {
  ServerOptions options;
  options.limits.max_targets = 3;
  options.limits.max_output_values = 8;
  options.limits.max_unary_response_bytes = 100;
  StartServer(options);
  ASSERT_TRUE(Upload(*stub_, GridOff(2, 2, true), "tiny").status.ok());
  auto expect = [](const grpc::Status& s, grpc::StatusCode code, const std::string& needle) {
    EXPECT_EQ(s.error_code(), code) << s.error_message();
    EXPECT_NE(s.error_message().find(needle), std::string::npos) << s.error_message();
  };
  v1::LocatePointsRequest l;
  l.set_mesh("meshes/tiny");
  for (int k = 0; k < 4; ++k) l.add_positions()->set_x(k);
  {
    grpc::ClientContext c;
    v1::LocatePointsResponse out;
    expect(stub_->LocatePoints(&c, l, &out), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max_targets");
  }
  l.mutable_positions()->RemoveLast();
  {
    grpc::ClientContext c;
    v1::LocatePointsResponse out;
    expect(stub_->LocatePoints(&c, l, &out), grpc::StatusCode::RESOURCE_EXHAUSTED,
           "--max_unary_response_bytes");
  }
  v1::ComputeDistanceMatrixRequest m;
  m.set_mesh("meshes/tiny");
  for (int k = 0; k < 3; ++k) {
    m.add_sources()->set_vertex(k);
    m.add_targets()->set_vertex(k);
  }
  grpc::ClientContext c;
  auto reader = stub_->ComputeDistanceMatrix(&c, m);
  v1::ComputeDistanceMatrixResponse r;
  while (reader->Read(&r)) {
  }
  expect(reader->Finish(), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max_output_values");
}

}  // namespace
}  // namespace geodex::server
