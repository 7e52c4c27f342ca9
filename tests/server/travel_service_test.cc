// Travel cost through geodexd (SolverOptions.travel): fields, paths, matrices and isolines equal
// core's answers bit for bit and say their bound (travel_epsilon); the result cache never serves a
// travel field for a plain request or another travel cost; errors name the option's field; the
// Steiner-point budget is a server flag. A slope-dependent speed (Tobler, a table, inbound) rides
// through too, equals core bit for bit and keys its own cache entries; paths refuse inbound.

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "field_cache.h"
#include "geodex/distance_matrix.h"
#include "geodex/friction.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geometry_queries.h"
#include "geodex/isolines.h"
#include "geodex/shortest_path.h"
#include "geodex/weighted_field.h"
#include "geometry_convert.h"
#include "mesh_store.h"
#include "proto_convert.h"
#include "server_test_util.h"
#include "service_limits.h"

namespace geodex::server {
namespace {

using testing::BadField;
using testing::BuildLocal;
using testing::Contains;
using testing::GridOff;
using testing::In;
using testing::Upload;

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <typename Response, typename Request, typename Method>
grpc::Status ReadAll(Method method, const Request& request, std::vector<Response>* out) {
  grpc::ClientContext context;
  context.set_deadline(In(300));
  auto reader = method(&context, request);
  Response response;
  while (reader->Read(&response)) out->push_back(response);
  return reader->Finish();
}

// The ErrorInfo of a status's details (reason, metadata).
google::rpc::ErrorInfo Info(const grpc::Status& status) {
  google::rpc::Status details;
  google::rpc::ErrorInfo info;
  EXPECT_TRUE(details.ParseFromString(status.error_details())) << status.error_message();
  for (const auto& any : details.details()) {
    if (any.UnpackTo(&info)) return info;
  }
  return info;
}

class TravelServiceTest : public testing::ServerFixture {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.limits.stream_chunk_bytes = 2000;  // many messages
    StartServer(options);
    off_ = GridOff(24, 18, true);
    testing::UploadResult up = Upload(*stub_, off_, "hills");
    ASSERT_TRUE(up.status.ok()) << up.status.error_message();
    local_ = std::make_unique<TriangleMesh>(BuildLocal(off_));
    faces_ = up.mesh.face_count();
  }

  // 4 km/h, a 5% bound, friction 1, 2 or 3 by face, cliffs over 40 degrees impassable.
  GeodesicOptions Travel() const {
    TravelCost travel;
    travel.speed_kmh = 4;
    travel.epsilon = 0.05;
    travel.max_slope_deg = 40;
    auto weights = std::make_shared<std::vector<double>>();
    for (uint64_t f = 0; f < faces_; ++f) weights->push_back(1.0 + static_cast<double>(f % 3));
    travel.face_weight = std::move(weights);
    travel.max_steiner_points = ServiceLimits().max_steiner_points;  // the server's default
    GeodesicOptions options;
    options.travel = travel;
    return options;
  }
  // Tobler's hiking function (or a speed table when given), a 5% Steiner density, no weights.
  GeodesicOptions SlopeTravel(bool inbound = false,
                              std::vector<std::array<double, 2>> table = {}) const {
    TravelCost travel;
    travel.speed_model = table.empty() ? SpeedModel::kTobler : SpeedModel::kTable;
    if (!table.empty()) {
      travel.speed_table =
          std::make_shared<const std::vector<std::array<double, 2>>>(std::move(table));
    }
    travel.inbound = inbound;
    travel.epsilon = 0.05;
    travel.max_steiner_points = ServiceLimits().max_steiner_points;
    GeodesicOptions options;
    options.travel = travel;
    return options;
  }
  // A walker's table: 5 km/h on the level, slower uphill than down, nothing beyond 35 degrees.
  static std::vector<std::array<double, 2>> WalkerTable() {
    return {{-35, 1}, {-10, 5.5}, {0, 5}, {10, 3.5}, {35, 0.5}};
  }
  // FindShortestPath on the uploaded mesh for `query`.
  grpc::Status PathOverService(const PathQuery& query, v1::FindShortestPathResponse* response) {
    v1::FindShortestPathRequest request;
    request.set_mesh("meshes/hills");
    api::PathQueryToProto(query, &request);
    grpc::ClientContext context;
    return stub_->FindShortestPath(&context, request, response);
  }
  std::vector<SurfacePoint> Sites() const {
    return {SurfacePoint::AtVertex(3), SurfacePoint::OnEdge(400, 401, 0.3),
            SurfacePoint::InFace(700, 0.2, 0.3, 0.5)};
  }

  struct Field {
    grpc::Status status;
    std::vector<double> distances;
    double travel_epsilon = -1;
    bool travel_exact = false;
    bool cached = false;
  };
  Field ReadField(const v1::ComputeDistanceFieldRequest& request) {
    std::vector<v1::ComputeDistanceFieldResponse> messages;
    Field out;
    out.status = ReadAll<v1::ComputeDistanceFieldResponse>(
        [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceField(c, r); },
        request, &messages);
    for (const auto& m : messages) {
      if (m.offset() == 0) out.travel_epsilon = m.travel_epsilon();
      if (m.offset() == 0) out.travel_exact = m.travel_exact();
      out.distances.insert(out.distances.end(), m.distances_f64().begin(), m.distances_f64().end());
      if (m.has_stats()) out.cached = m.stats().cached();
    }
    return out;
  }
  v1::ComputeDistanceFieldRequest FieldRequestOf(const GeodesicOptions& options) const {
    v1::ComputeDistanceFieldRequest request;
    request.set_mesh("meshes/hills");
    request.set_want_stats(true);
    FieldQuery query;
    query.sources = Sites();
    query.options = options;
    api::FieldQueryToProto(query, &request);
    return request;
  }

  std::string off_;
  std::unique_ptr<TriangleMesh> local_;
  uint64_t faces_ = 0;
};

TEST_F(TravelServiceTest, SolverOptionsRoundTrip) {
  v1::SolverOptions proto;
  api::SolverOptionsToProto(Travel(), &proto);
  ASSERT_TRUE(proto.has_travel());
  EXPECT_EQ(proto.travel().face_weights_size(), static_cast<int>(faces_));
  absl::StatusOr<GeodesicOptions> back = SolverOptionsFromProto(proto, 0, 77, "options");
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_TRUE(back->travel.has_value());
  EXPECT_EQ(back->travel->speed_kmh, 4);
  EXPECT_EQ(back->travel->epsilon, 0.05);
  EXPECT_EQ(back->travel->max_slope_deg, 40);
  EXPECT_EQ(back->travel->max_steiner_points, 77u);
  // The whole mapping comes back, face weights included (one place: proto/convert).
  ASSERT_NE(back->travel->face_weight, nullptr);
  EXPECT_EQ(*back->travel->face_weight, *Travel().travel->face_weight);
  EXPECT_EQ(back->max_windows, 0u);
  // Both ways of giving weights at once: refused naming the field, as the server words it.
  proto.mutable_travel()->set_friction_geojson("{}");
  absl::StatusOr<GeodesicOptions> both = SolverOptionsFromProto(proto, 0, 77, "pairs[1].options");
  EXPECT_EQ(both.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(
      absl::StartsWith(both.status().message(), "pairs[1].options.travel.friction_geojson: "))
      << both.status();
  // Without a travel cost none comes back; an unset epsilon is core's default.
  v1::SolverOptions plain;
  EXPECT_FALSE(SolverOptionsFromProto(plain, 0, 0, "options")->travel.has_value());
  plain.mutable_travel()->set_speed_kmh(5);
  EXPECT_EQ(SolverOptionsFromProto(plain, 0, 0, "options")->travel->epsilon, TravelCost().epsilon);
  // A field's bound rides in its first message and comes back through the client's assembler.
  DistanceField field;
  field.distance = {0, 1.5};
  field.source = {0, 0};
  field.travel_epsilon = 0.05;
  field.travel_exact = true;
  v1::ComputeDistanceFieldResponse first, second;
  api::FieldChunkToProto(field, DistanceField(), 0, 1, {}, &first);
  api::FieldChunkToProto(field, DistanceField(), 1, 2, {}, &second);
  EXPECT_EQ(first.travel_epsilon(), 0.05);
  EXPECT_EQ(second.travel_epsilon(), 0);  // only in the first message
  api::FieldAssembler assembler;
  assembler.Add(first);
  assembler.Add(second);
  EXPECT_EQ(assembler.result().travel_epsilon, 0.05);
  EXPECT_TRUE(first.travel_exact());
  EXPECT_TRUE(assembler.result().travel_exact);
  EXPECT_EQ(assembler.result().distance, field.distance);
  // The slope-dependent speed round-trips: model, table rows, inbound.
  GeodesicOptions table = SlopeTravel(/*inbound=*/true, WalkerTable());
  v1::SolverOptions table_proto;
  api::SolverOptionsToProto(table, &table_proto);
  EXPECT_EQ(table_proto.travel().speed_model(), v1::SPEED_MODEL_TABLE);
  ASSERT_EQ(table_proto.travel().speed_table_size(), 5);
  EXPECT_EQ(table_proto.travel().speed_table(1).slope_deg(), -10);
  EXPECT_EQ(table_proto.travel().speed_table(1).speed_kmh(), 5.5);
  EXPECT_TRUE(table_proto.travel().inbound());
  absl::StatusOr<GeodesicOptions> table_back =
      SolverOptionsFromProto(table_proto, 0, 77, "options");
  ASSERT_TRUE(table_back.ok()) << table_back.status();
  EXPECT_EQ(table_back->travel->speed_model, SpeedModel::kTable);
  ASSERT_NE(table_back->travel->speed_table, nullptr);
  EXPECT_EQ(*table_back->travel->speed_table, WalkerTable());
  EXPECT_TRUE(table_back->travel->inbound);
  EXPECT_EQ(table_back->travel->speed_kmh, 0);
  v1::SolverOptions tobler_proto;
  api::SolverOptionsToProto(SlopeTravel(), &tobler_proto);
  EXPECT_EQ(tobler_proto.travel().speed_model(), v1::SPEED_MODEL_TOBLER);
  EXPECT_EQ(tobler_proto.travel().speed_table_size(), 0);
  EXPECT_FALSE(tobler_proto.travel().inbound());
  absl::StatusOr<GeodesicOptions> tobler_back =
      SolverOptionsFromProto(tobler_proto, 0, 77, "options");
  ASSERT_TRUE(tobler_back.ok()) << tobler_back.status();
  EXPECT_EQ(tobler_back->travel->speed_model, SpeedModel::kTobler);
  EXPECT_EQ(tobler_back->travel->speed_table, nullptr);
  EXPECT_FALSE(tobler_back->travel->inbound);
  // An unset model is the constant speed (an old client's request).
  EXPECT_EQ(SolverOptionsFromProto(plain, 0, 0, "options")->travel->speed_model,
            SpeedModel::kConstant);
  EXPECT_EQ(proto.travel().speed_model(), v1::SPEED_MODEL_CONSTANT);
  EXPECT_EQ(OptionFieldName("travel.speed_table[3]"), "options.travel.speed_table[3]");
  EXPECT_EQ(OptionFieldName("travel.speed_table", "pairs[2].options"),
            "pairs[2].options.travel.speed_table");
  EXPECT_EQ(OptionFieldName("face_weight[7]"), "options.travel.face_weights[7]");
  EXPECT_EQ(OptionFieldName("travel.speed_kmh"), "options.travel.speed_kmh");
  EXPECT_EQ(OptionFieldName("lambda"), "options.lambda");
}

TEST_F(TravelServiceTest, FieldPathMatrixAndIsolinesEqualCore) {
  const GeodesicOptions options = Travel();
  // The field.
  absl::StatusOr<DistanceField> want = ComputeDistanceField(*local_, Sites(), options);
  ASSERT_TRUE(want.ok()) << want.status();
  Field got = ReadField(FieldRequestOf(options));
  ASSERT_TRUE(got.status.ok()) << got.status.error_message();
  EXPECT_EQ(got.travel_epsilon, 0.05);
  EXPECT_EQ(got.travel_exact, TravelIsExact(*options.travel));  // the answer says which it is
  EXPECT_EQ(got.travel_exact, want->travel_exact);
  ASSERT_EQ(got.distances.size(), want->distance.size());
  size_t finite = 0;
  for (size_t v = 0; v < got.distances.size(); ++v) {
    EXPECT_TRUE(BitEqual(got.distances[v], want->distance[v])) << v;
    finite += std::isfinite(got.distances[v]);
  }
  EXPECT_GT(finite, got.distances.size() / 2);

  // A path (from a point whose field is cached: a travel path is still its own solve).
  PathQuery path_query{Sites()[0], SurfacePoint::AtVertex(420), {}};
  path_query.options.solver = options;
  absl::StatusOr<PathQueryResult> want_path =
      ComputeShortestPath(*local_, path_query.from, path_query.to, path_query.options);
  ASSERT_TRUE(want_path.ok()) << want_path.status();
  for (int repeat = 0; repeat < 3; ++repeat) {
    v1::FindShortestPathResponse response;
    grpc::Status status = PathOverService(path_query, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_TRUE(BitEqual(response.distance(), want_path->distance));
    EXPECT_EQ(response.travel_epsilon(), 0.05);
    EXPECT_EQ(response.travel_exact(), TravelIsExact(*options.travel));
    ASSERT_EQ(response.points_size(), static_cast<int>(want_path->path.points.size()));
    for (int i = 0; i < response.points_size(); ++i) {
      EXPECT_TRUE(
          BitEqual(response.points(i).position().x(), want_path->path.points[i].position[0]));
      EXPECT_TRUE(
          BitEqual(response.points(i).position().y(), want_path->path.points[i].position[1]));
    }
  }
  // FindShortestPaths: the same time, the bound on the response and on each path.
  {
    v1::FindShortestPathsRequest request;
    request.set_mesh("meshes/hills");
    v1::ShortestPathPair* pair = request.add_pairs();
    SurfacePointToProto(path_query.from, pair->mutable_from());
    SurfacePointToProto(path_query.to, pair->mutable_to());
    api::SolverOptionsToProto(options, request.mutable_options());
    v1::FindShortestPathsResponse response;
    grpc::ClientContext context;
    grpc::Status status = stub_->FindShortestPaths(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(response.travel_epsilon(), 0.05);
    ASSERT_EQ(response.paths_size(), 1);
    EXPECT_EQ(response.paths(0).travel_epsilon(), 0.05);
    EXPECT_TRUE(BitEqual(response.paths(0).distance(), want_path->distance));
  }

  // A matrix (not symmetric: sources and targets differ).
  MatrixQuery matrix_query;
  matrix_query.sources = Sites();
  for (uint32_t v = 5; v < 475; v += 41) matrix_query.targets.push_back(SurfacePoint::AtVertex(v));
  matrix_query.targets.push_back(SurfacePoint::InFace(100, 0.5, 0.25, 0.25));
  matrix_query.options.solver = options;
  matrix_query.options.threads = 1;
  absl::StatusOr<DistanceMatrix> want_matrix = ComputeDistanceMatrix(
      *local_, matrix_query.sources, matrix_query.targets, matrix_query.options);
  ASSERT_TRUE(want_matrix.ok()) << want_matrix.status();
  {
    v1::ComputeDistanceMatrixRequest request;
    request.set_mesh("meshes/hills");
    api::MatrixQueryToProto(matrix_query, &request);
    std::vector<v1::ComputeDistanceMatrixResponse> messages;
    grpc::Status status = ReadAll<v1::ComputeDistanceMatrixResponse>(
        [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
        request, &messages);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_FALSE(messages.empty());
    EXPECT_EQ(messages.front().travel_epsilon(), 0.05);
    std::vector<double> values;
    for (const auto& m : messages) {
      values.insert(values.end(), m.values_f64().begin(), m.values_f64().end());
    }
    ASSERT_EQ(values.size(), want_matrix->values.size());
    for (size_t i = 0; i < values.size(); ++i) {
      EXPECT_TRUE(BitEqual(values[i], want_matrix->values[i])) << i;
    }
  }

  // Isolines of the (cached) travel field, levels in seconds.
  IsolineQuery iso_query;
  iso_query.sources = Sites();
  iso_query.options = options;
  iso_query.levels.count = 5;
  absl::StatusOr<Isolines> want_iso = ExtractIsolines(*local_, *want, iso_query.levels);
  ASSERT_TRUE(want_iso.ok()) << want_iso.status();
  ASSERT_FALSE(want_iso->polylines.empty());
  {
    v1::ComputeIsolinesRequest request;
    request.set_mesh("meshes/hills");
    api::IsolineQueryToProto(iso_query, &request);
    std::vector<v1::ComputeIsolinesResponse> messages;
    grpc::Status status = ReadAll<v1::ComputeIsolinesResponse>(
        [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeIsolines(c, r); },
        request, &messages);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(messages.front().travel_epsilon(), 0.05);
    std::vector<double> levels(messages.front().levels().begin(), messages.front().levels().end());
    ASSERT_EQ(levels.size(), want_iso->levels.size());
    for (size_t i = 0; i < levels.size(); ++i)
      EXPECT_TRUE(BitEqual(levels[i], want_iso->levels[i]));
    size_t points = 0, want_points = 0;
    for (const auto& m : messages) {
      for (const auto& line : m.isolines()) points += line.points_size();
    }
    for (const IsolinePolyline& line : want_iso->polylines) want_points += line.points.size();
    EXPECT_EQ(points, want_points);
  }

  // Voronoi of the travel field says its bound too.
  {
    v1::ComputeVoronoiRequest request;
    request.set_mesh("meshes/hills");
    for (const SurfacePoint& p : Sites()) SurfacePointToProto(p, request.add_sources());
    api::SolverOptionsToProto(options, request.mutable_options());
    std::vector<v1::ComputeVoronoiResponse> messages;
    grpc::Status status = ReadAll<v1::ComputeVoronoiResponse>(
        [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeVoronoi(c, r); }, request,
        &messages);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(messages.front().travel_epsilon(), 0.05);
  }
  // EstimateDistances, EXACT: core's point values in seconds.
  {
    v1::EstimateDistancesRequest request;
    request.set_mesh("meshes/hills");
    PointQuery query{Sites(), matrix_query.targets, options, false};
    api::PointQueryToProto(query, &request);
    request.set_mode(v1::POINT_DISTANCE_MODE_EXACT);
    v1::EstimateDistancesResponse response;
    grpc::ClientContext context;
    grpc::Status status = stub_->EstimateDistances(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(response.travel_epsilon(), 0.05);
    absl::StatusOr<PointValues> values = ComputePointValues(*local_, query);
    ASSERT_TRUE(values.ok()) << values.status();
    ASSERT_EQ(response.exact_size(), static_cast<int>(values->distance.size()));
    for (int i = 0; i < response.exact_size(); ++i) {
      EXPECT_TRUE(BitEqual(response.exact(i), values->distance[i])) << i;
    }
  }
  // Several weights: the paths, the matrix and the point times run on regions built for their
  // points (SharesTravelSurface is false), as the field does: nothing is looked up or shared, and
  // a path's time is the field's at its end. All equal core's own.
  EXPECT_EQ(server_->cache().graph_misses(), 0u);
  EXPECT_EQ(server_->cache().graph_hits(), 0u);
  EXPECT_EQ(server_->cache().entries(), 2u);  // the field and the matrix
}

// One weight (no friction, steep faces impassable): the exact engine's surface, no Steiner graph,
// cached and shared as a graph is, also by queries from and to points inside faces and on edges
// (it needs no refining around them); its answers are core's, bit for bit.
TEST_F(TravelServiceTest, OneWeightSurfaceIsSharedAsAGraphIs) {
  GeodesicOptions one = Travel();
  one.travel->face_weight = nullptr;
  // The first query starts inside a face: it builds the surface all the others share.
  const std::vector<std::pair<SurfacePoint, SurfacePoint>> queries = {
      {Sites()[2], SurfacePoint::AtVertex(420)},
      {Sites()[0], SurfacePoint::AtVertex(300)},
      {Sites()[1], Sites()[2]}};
  for (size_t i = 0; i < queries.size(); ++i) {
    PathQuery query{queries[i].first, queries[i].second, {}};
    query.options.solver = one;
    v1::FindShortestPathResponse response;
    grpc::Status status = PathOverService(query, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    absl::StatusOr<PathQueryResult> want =
        ComputeShortestPath(*local_, query.from, query.to, query.options);
    ASSERT_TRUE(want.ok()) << want.status();
    EXPECT_TRUE(BitEqual(response.distance(), want->distance)) << i;
  }
  EXPECT_EQ(server_->cache().graph_misses(), 1u);
  EXPECT_EQ(server_->cache().graph_hits(), 2u);
  absl::StatusOr<std::shared_ptr<const StoredMesh>> stored = server_->store().Get("hills");
  ASSERT_TRUE(stored.ok()) << stored.status();
  std::shared_ptr<const WeightedSurface> surface =
      server_->cache().FindGraph(TravelSurfaceKey((*stored)->id, one), *(*stored)->mesh);
  ASSERT_NE(surface, nullptr);
  EXPECT_EQ(surface->steiner_points(), 0u);
}

// geodexd's work budget (--max_windows, on by default) bounds every travel solve: a path with
// several weights (the regions: windows) and one at Tobler's speed (the graph: links relaxed, 32
// a window) on a server whose budget is too small are RESOURCE_EXHAUSTED naming the flag, and
// the default budget answers both. Before, the graph ignored the budget.
TEST_F(TravelServiceTest, WorkBudgetBoundsTravelGraphSearches) {
  EXPECT_EQ(ServiceLimits().max_windows, kServerDefaultMaxWindows);
  EXPECT_EQ(ServiceLimits().max_steiner_points, kDefaultMaxSteinerPoints);
  PathQuery friction{Sites()[0], SurfacePoint::AtVertex(420), {}};
  friction.options.solver = Travel();
  PathQuery tobler = friction;
  tobler.options.solver = SlopeTravel();
  v1::FindShortestPathResponse response;
  ASSERT_TRUE(PathOverService(friction, &response).ok());  // the default budget
  ASSERT_TRUE(PathOverService(tobler, &response).ok());
  server_->Shutdown(absl::Now());
  ServerOptions options;
  options.limits.max_windows = 2;
  StartServer(options);
  ASSERT_TRUE(Upload(*stub_, off_, "hills").status.ok());
  for (const PathQuery& query : {friction, tobler}) {
    grpc::Status status = PathOverService(query, &response);
    ASSERT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
    EXPECT_NE(status.error_message().find("--max_windows"), std::string::npos)
        << status.error_message();
    EXPECT_EQ(Info(status).metadata().at("flag"), "max_windows");
  }
  grpc::Status status = PathOverService(tobler, &response);
  EXPECT_NE(status.error_message().find("work budget exceeded: the travel graph's search"),
            std::string::npos)
      << status.error_message();
}

// Shared travel surfaces in the result cache (one weight: the exact engine's on the passable
// faces; several weights and slope speeds share nothing): one per mesh and travel cost (another
// epsilon is another), counted in its bytes, serving any point, and what its answers are does not
// depend on whether it came from the cache.
TEST_F(TravelServiceTest, TravelQueriesShareOneGraphPerCost) {
  GeodesicOptions one = Travel();
  one.travel->face_weight = nullptr;
  auto path = [&](const GeodesicOptions& options, uint32_t to) {
    PathQuery query{Sites()[0], SurfacePoint::AtVertex(to), {}};
    query.options.solver = options;
    v1::FindShortestPathResponse response;
    grpc::Status status = PathOverService(query, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    absl::StatusOr<PathQueryResult> want =
        ComputeShortestPath(*local_, query.from, query.to, query.options);
    EXPECT_TRUE(want.ok()) << want.status();
    if (want.ok()) {
      EXPECT_TRUE(BitEqual(response.distance(), want->distance));
    }
  };
  const uint64_t empty = server_->cache().bytes();
  path(one, 420);
  EXPECT_EQ(server_->cache().graph_misses(), 1u);
  EXPECT_EQ(server_->cache().entries(), 1u);  // the surface
  EXPECT_GT(server_->cache().bytes(), empty);
  path(one, 300);
  path(one, 12);
  EXPECT_EQ(server_->cache().graph_hits(), 2u);
  GeodesicOptions finer = one;
  finer.travel->epsilon = 0.03;
  path(finer, 420);
  path(finer, 300);
  EXPECT_EQ(server_->cache().graph_misses(), 2u);
  EXPECT_EQ(server_->cache().graph_hits(), 3u);
  EXPECT_EQ(server_->cache().entries(), 2u);
  path(SlopeTravel(), 420);  // its points follow each query's sources: nothing to share
  path(Travel(), 420);       // several weights: regions around its ends, nothing shared
  EXPECT_EQ(server_->cache().graph_misses(), 2u);
  EXPECT_EQ(server_->cache().graph_hits(), 3u);
  {
    // A point inside a face: the surface takes it as it is (a hit), answering as core does.
    PathQuery query{Sites()[2], SurfacePoint::AtVertex(420), {}};
    query.options.solver = one;
    v1::FindShortestPathResponse response;
    ASSERT_TRUE(PathOverService(query, &response).ok());
    absl::StatusOr<PathQueryResult> want =
        ComputeShortestPath(*local_, query.from, query.to, query.options);
    ASSERT_TRUE(want.ok()) << want.status();
    EXPECT_TRUE(BitEqual(response.distance(), want->distance));
    EXPECT_EQ(server_->cache().graph_misses(), 2u);
    EXPECT_EQ(server_->cache().graph_hits(), 4u);
    EXPECT_EQ(server_->cache().entries(), 2u);
  }

  // A graph keeps its mesh alive, so its entry counts the mesh's memory as well as its own.
  absl::StatusOr<std::shared_ptr<const StoredMesh>> stored = server_->store().Get("hills");
  ASSERT_TRUE(stored.ok()) << stored.status();
  const std::string key = TravelSurfaceKey((*stored)->id, one);
  std::shared_ptr<const WeightedSurface> graph = server_->cache().FindGraph(key, *(*stored)->mesh);
  ASSERT_NE(graph, nullptr);
  EXPECT_EQ(&graph->mesh(), (*stored)->mesh.get());
  const std::string finer_key = TravelSurfaceKey((*stored)->id, finer);
  std::shared_ptr<const WeightedSurface> finer_graph =
      server_->cache().FindGraph(finer_key, *(*stored)->mesh);
  ASSERT_NE(finer_graph, nullptr);
  EXPECT_EQ(server_->cache().bytes() - empty, graph->bytes() + finer_graph->bytes() +
                                                  2 * (*stored)->memory_bytes + key.size() +
                                                  finer_key.size());
  // The mesh deleted and uploaded again is another object: its next travel path replaces the
  // graph (one entry, on the new mesh) rather than searching the old one, and counts as the miss
  // it is (it builds).
  ASSERT_TRUE(server_->store().Delete((*stored)->id).ok());
  graph.reset();
  finer_graph.reset();
  ASSERT_TRUE(Upload(*stub_, off_, "hills").status.ok());
  const uint64_t hits = server_->cache().graph_hits();
  const uint64_t misses = server_->cache().graph_misses();
  path(one, 420);
  EXPECT_EQ(server_->cache().graph_misses(), misses + 1);
  EXPECT_EQ(server_->cache().graph_hits(), hits);
  absl::StatusOr<std::shared_ptr<const StoredMesh>> again = server_->store().Get("hills");
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_NE(again->get(), stored->get());
  EXPECT_EQ(server_->cache().FindGraph(key, *(*stored)->mesh), nullptr);  // the old mesh's: gone
  graph = server_->cache().FindGraph(key, *(*again)->mesh);
  ASSERT_NE(graph, nullptr);
  EXPECT_EQ(&graph->mesh(), (*again)->mesh.get());
  EXPECT_EQ(server_->cache().entries(), 2u);
}

TEST_F(TravelServiceTest, CacheNeverMixesTravelAndPlainFields) {
  const GeodesicOptions travel = Travel();
  const DistanceField plain_want = *ComputeDistanceField(*local_, Sites());
  const DistanceField travel_want = *ComputeDistanceField(*local_, Sites(), travel);

  Field first = ReadField(FieldRequestOf(travel));
  ASSERT_TRUE(first.status.ok()) << first.status.error_message();
  EXPECT_FALSE(first.cached);
  // The same sources without a travel cost: solved, in metres, exact.
  Field plain = ReadField(FieldRequestOf(GeodesicOptions()));
  ASSERT_TRUE(plain.status.ok()) << plain.status.error_message();
  EXPECT_FALSE(plain.cached);
  EXPECT_EQ(plain.travel_epsilon, 0);
  ASSERT_EQ(plain.distances.size(), plain_want.distance.size());
  for (size_t v = 0; v < plain.distances.size(); ++v) {
    ASSERT_TRUE(BitEqual(plain.distances[v], plain_want.distance[v])) << v;
  }
  // Each again: from the cache, each its own.
  Field travel_again = ReadField(FieldRequestOf(travel));
  EXPECT_TRUE(travel_again.cached);
  EXPECT_EQ(travel_again.travel_epsilon, 0.05);
  EXPECT_EQ(travel_again.distances, travel_want.distance);
  Field plain_again = ReadField(FieldRequestOf(GeodesicOptions()));
  EXPECT_TRUE(plain_again.cached);
  EXPECT_EQ(plain_again.travel_epsilon, 0);
  EXPECT_EQ(plain_again.distances, plain_want.distance);
  // Another travel cost (other weights, speed, bound or slope) is another field.
  GeodesicOptions other = travel;
  auto weights = std::make_shared<std::vector<double>>(*travel.travel->face_weight);
  (*weights)[5] = 7;
  other.travel->face_weight = weights;
  EXPECT_FALSE(ReadField(FieldRequestOf(other)).cached);
  other = travel;
  other.travel->speed_kmh = 5;
  EXPECT_FALSE(ReadField(FieldRequestOf(other)).cached);
  other = travel;
  other.travel->max_slope_deg = 0;
  EXPECT_FALSE(ReadField(FieldRequestOf(other)).cached);
  other = travel;
  other.travel->face_weight = nullptr;
  EXPECT_FALSE(ReadField(FieldRequestOf(other)).cached);
  // At a constant speed times are the same both ways: inbound is the same field, from the cache.
  other = travel;
  other.travel->inbound = true;
  Field inbound = ReadField(FieldRequestOf(other));
  EXPECT_TRUE(inbound.cached);
  EXPECT_EQ(inbound.distances, travel_want.distance);
}

TEST_F(TravelServiceTest, FrictionPolygonsWeighTheirFaces) {
  // Friction 4 over x in [0, 10] in the mesh's own x y: the field equals core's with the weights
  // terrain reads from the same text.
  const std::string geojson =
      R"({"type": "FeatureCollection", "features": [{"type": "Feature",
          "properties": {"friction": 4},
          "geometry": {"type": "Polygon",
                       "coordinates": [[[-1, -1], [10, -1], [10, 20], [-1, 20], [-1, -1]]]}}]})";
  absl::StatusOr<MeshData> data = ReadMeshFromBuffer(off_, MeshFormat::kOff, "local.off");
  ASSERT_TRUE(data.ok());
  absl::StatusOr<std::vector<double>> friction =
      terrain::FrictionFromGeoJson(*data, geojson, nullptr, "friction");
  ASSERT_TRUE(friction.ok()) << friction.status();
  GeodesicOptions options = Travel();
  options.travel->face_weight = std::make_shared<const std::vector<double>>(*friction);
  const DistanceField want = *ComputeDistanceField(*local_, Sites(), options);

  GeodesicOptions request_options = Travel();
  request_options.travel->face_weight = nullptr;
  v1::ComputeDistanceFieldRequest request = FieldRequestOf(request_options);
  request.mutable_options()->mutable_travel()->set_friction_geojson(geojson);
  Field got = ReadField(request);
  ASSERT_TRUE(got.status.ok()) << got.status.error_message();
  EXPECT_EQ(got.travel_epsilon, 0.05);
  EXPECT_EQ(got.distances, want.distance);
  // The same weights given as face_weights are the same field (from the cache), and so is the
  // same text again (its friction cached too: answered without reading the polygons).
  Field same = ReadField(FieldRequestOf(options));
  EXPECT_TRUE(same.cached);
  EXPECT_EQ(same.distances, want.distance);
  Field again = ReadField(request);
  ASSERT_TRUE(again.status.ok()) << again.status.error_message();
  EXPECT_TRUE(again.cached);
  EXPECT_EQ(again.distances, want.distance);

  // Text that is not friction polygons names the field.
  request.mutable_options()->mutable_travel()->set_friction_geojson("{not json");
  Field bad = ReadField(request);
  EXPECT_EQ(bad.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(bad.status), "options.travel.friction_geojson") << bad.status.error_message();
}

TEST_F(TravelServiceTest, SlopeSpeedFieldsPathsAndMatricesEqualCore) {
  // Tobler's speed, from the sources and towards them: each equals core's bit for bit and says
  // its epsilon (the Steiner density; no bound is proved with a slope-dependent speed).
  std::vector<double> outbound;
  for (bool inbound : {false, true}) {
    const GeodesicOptions options = SlopeTravel(inbound);
    absl::StatusOr<DistanceField> want = ComputeDistanceField(*local_, Sites(), options);
    ASSERT_TRUE(want.ok()) << want.status();
    Field got = ReadField(FieldRequestOf(options));
    ASSERT_TRUE(got.status.ok()) << got.status.error_message();
    EXPECT_FALSE(got.cached);
    EXPECT_EQ(got.travel_epsilon, 0.05);
    ASSERT_EQ(got.distances.size(), want->distance.size());
    size_t finite = 0;
    for (size_t v = 0; v < got.distances.size(); ++v) {
      ASSERT_TRUE(BitEqual(got.distances[v], want->distance[v])) << inbound << " " << v;
      finite += std::isfinite(got.distances[v]);
    }
    EXPECT_EQ(finite, got.distances.size());  // Tobler walks every slope of the hills
    if (!inbound) {
      outbound = got.distances;
      continue;
    }
    // On the hills times towards the sources are not times from them: uphill is slower.
    size_t differ = 0;
    for (size_t v = 0; v < got.distances.size(); ++v) {
      differ += std::abs(got.distances[v] - outbound[v]) > 1e-6 * outbound[v];
    }
    EXPECT_GT(differ, got.distances.size() / 2);
  }
  // A speed table through the service equals core's too.
  {
    const GeodesicOptions options = SlopeTravel(false, WalkerTable());
    absl::StatusOr<DistanceField> want = ComputeDistanceField(*local_, Sites(), options);
    ASSERT_TRUE(want.ok()) << want.status();
    Field got = ReadField(FieldRequestOf(options));
    ASSERT_TRUE(got.status.ok()) << got.status.error_message();
    ASSERT_EQ(got.distances.size(), want->distance.size());
    for (size_t v = 0; v < got.distances.size(); ++v) {
      ASSERT_TRUE(BitEqual(got.distances[v], want->distance[v])) << v;
    }
  }
  // A path is walked from its start and equals core's; the way back (the ends swapped) takes
  // another time.
  std::vector<double> times;
  for (bool back : {false, true}) {
    PathQuery path_query{Sites()[0], SurfacePoint::AtVertex(420), {}};
    if (back) std::swap(path_query.from, path_query.to);
    path_query.options.solver = SlopeTravel();
    absl::StatusOr<PathQueryResult> want =
        ComputeShortestPath(*local_, path_query.from, path_query.to, path_query.options);
    ASSERT_TRUE(want.ok()) << want.status();
    v1::FindShortestPathResponse response;
    grpc::Status status = PathOverService(path_query, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_TRUE(BitEqual(response.distance(), want->distance));
    EXPECT_EQ(response.travel_epsilon(), 0.05);
    EXPECT_EQ(response.points_size(), static_cast<int>(want->path.points.size()));
    times.push_back(response.distance());
  }
  EXPECT_NE(times[0], times[1]);
  // A path refuses inbound (core's rule), naming the field.
  {
    PathQuery path_query{Sites()[0], SurfacePoint::AtVertex(420), {}};
    path_query.options.solver = SlopeTravel(/*inbound=*/true);
    v1::FindShortestPathRequest request;
    request.set_mesh("meshes/hills");
    api::PathQueryToProto(path_query, &request);
    EXPECT_TRUE(request.options().travel().inbound());
    v1::FindShortestPathResponse response;
    grpc::ClientContext context;
    grpc::Status status = stub_->FindShortestPath(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(BadField(status), "options.travel.inbound") << status.error_message();
  }
  // A matrix of the same points both ways is not symmetric (row to column) and equals core's.
  MatrixQuery matrix_query;
  matrix_query.sources = {SurfacePoint::AtVertex(3), SurfacePoint::AtVertex(212),
                          SurfacePoint::AtVertex(420)};
  matrix_query.targets = matrix_query.sources;
  matrix_query.options.solver = SlopeTravel();
  matrix_query.options.threads = 1;
  absl::StatusOr<DistanceMatrix> want_matrix = ComputeDistanceMatrix(
      *local_, matrix_query.sources, matrix_query.targets, matrix_query.options);
  ASSERT_TRUE(want_matrix.ok()) << want_matrix.status();
  v1::ComputeDistanceMatrixRequest request;
  request.set_mesh("meshes/hills");
  api::MatrixQueryToProto(matrix_query, &request);
  std::vector<v1::ComputeDistanceMatrixResponse> messages;
  grpc::Status status = ReadAll<v1::ComputeDistanceMatrixResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
      request, &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::vector<double> values;
  for (const auto& m : messages) {
    values.insert(values.end(), m.values_f64().begin(), m.values_f64().end());
  }
  ASSERT_EQ(values.size(), 9u);
  ASSERT_EQ(values.size(), want_matrix->values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    EXPECT_TRUE(BitEqual(values[i], want_matrix->values[i])) << i;
  }
  EXPECT_NE(values[0 * 3 + 2], values[2 * 3 + 0]);
  // A row read from a cached one-source field (vertex targets, not the same points) is the row
  // core solves, from the source or (inbound) towards it.
  for (bool inbound : {false, true}) {
    const GeodesicOptions options = SlopeTravel(inbound);
    v1::ComputeDistanceFieldRequest field_request;
    field_request.set_mesh("meshes/hills");
    FieldQuery field_query;
    field_query.sources = {SurfacePoint::AtVertex(212)};
    field_query.options = options;
    api::FieldQueryToProto(field_query, &field_request);
    ASSERT_TRUE(ReadField(field_request).status.ok());
    MatrixQuery row_query;
    row_query.sources = field_query.sources;
    for (uint32_t v = 7; v < 475; v += 53) row_query.targets.push_back(SurfacePoint::AtVertex(v));
    row_query.options.solver = options;
    row_query.options.threads = 1;
    absl::StatusOr<DistanceMatrix> want_row =
        ComputeDistanceMatrix(*local_, row_query.sources, row_query.targets, row_query.options);
    ASSERT_TRUE(want_row.ok()) << want_row.status();
    v1::ComputeDistanceMatrixRequest row_request;
    row_request.set_mesh("meshes/hills");
    row_request.set_want_stats(true);
    api::MatrixQueryToProto(row_query, &row_request);
    std::vector<v1::ComputeDistanceMatrixResponse> row_messages;
    grpc::Status row_status = ReadAll<v1::ComputeDistanceMatrixResponse>(
        [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
        row_request, &row_messages);
    ASSERT_TRUE(row_status.ok()) << row_status.error_message();
    std::vector<double> row;
    bool row_cached = false;
    for (const auto& m : row_messages) {
      row.insert(row.end(), m.values_f64().begin(), m.values_f64().end());
      if (m.has_stats()) row_cached = m.stats().cached();
    }
    EXPECT_TRUE(row_cached) << inbound;
    ASSERT_EQ(row.size(), want_row->values.size());
    for (size_t i = 0; i < row.size(); ++i) {
      EXPECT_TRUE(BitEqual(row[i], want_row->values[i])) << inbound << " " << i;
    }
  }
  // Inbound, entry [i][j] is the time from target j to source i: the outbound [j][i].
  matrix_query.options.solver = SlopeTravel(/*inbound=*/true);
  request.Clear();
  request.set_mesh("meshes/hills");
  api::MatrixQueryToProto(matrix_query, &request);
  messages.clear();
  status = ReadAll<v1::ComputeDistanceMatrixResponse>(
      [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDistanceMatrix(c, r); },
      request, &messages);
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::vector<double> inbound;
  for (const auto& m : messages) {
    inbound.insert(inbound.end(), m.values_f64().begin(), m.values_f64().end());
  }
  ASSERT_EQ(inbound.size(), 9u);
  for (size_t i = 0; i < 3; ++i) {
    for (size_t j = 0; j < 3; ++j) {
      // Within the discretisation: a slope cost's search crosses between Steiner points, which
      // a search from the other end approximates differently.
      EXPECT_NEAR(inbound[i * 3 + j], values[j * 3 + i], 0.01 * values[j * 3 + i]) << i << j;
    }
  }
}

TEST_F(TravelServiceTest, CacheKeepsSpeedModelsTablesAndDirectionsApart) {
  // A constant speed, Tobler outbound and inbound, a table, another table: each its own solve,
  // then each again from the cache with its own values. The constant speed inbound takes the same
  // times: it is the constant speed's entry, from the cache the first time.
  GeodesicOptions constant = Travel();
  constant.travel->face_weight = nullptr;
  constant.travel->max_slope_deg = 0;
  GeodesicOptions constant_inbound = constant;
  constant_inbound.travel->inbound = true;
  std::vector<std::array<double, 2>> other_table = WalkerTable();
  other_table[2][1] = 4.5;  // one speed differs
  const std::vector<GeodesicOptions> all = {constant,
                                            SlopeTravel(false),
                                            SlopeTravel(true),
                                            SlopeTravel(false, WalkerTable()),
                                            SlopeTravel(false, other_table),
                                            SlopeTravel(true, WalkerTable()),
                                            constant_inbound};
  std::vector<std::vector<double>> first;
  for (size_t i = 0; i < all.size(); ++i) {
    Field got = ReadField(FieldRequestOf(all[i]));
    ASSERT_TRUE(got.status.ok()) << i << ": " << got.status.error_message();
    EXPECT_EQ(got.cached, i + 1 == all.size()) << i;
    first.push_back(got.distances);
  }
  for (size_t i = 0; i < all.size(); ++i) {
    Field again = ReadField(FieldRequestOf(all[i]));
    ASSERT_TRUE(again.status.ok()) << i << ": " << again.status.error_message();
    EXPECT_TRUE(again.cached) << i;
    EXPECT_EQ(again.distances, first[i]) << i;
  }
  // A constant speed is the same both ways (one entry for both directions), and the
  // slope-dependent ones differ from each other (the cache would have hidden a mix-up).
  EXPECT_EQ(first.front(), first.back());
  for (size_t i = 1; i + 1 < all.size(); ++i) {
    for (size_t j = i + 1; j + 1 < all.size(); ++j) EXPECT_NE(first[i], first[j]) << i << " " << j;
  }
}

TEST_F(TravelServiceTest, SlopeSpeedErrorsNameTheirField) {
  auto field_error = [&](const v1::ComputeDistanceFieldRequest& request) {
    Field got = ReadField(request);
    EXPECT_EQ(got.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << got.status.error_message();
    return std::make_pair(BadField(got.status), got.status.error_message());
  };
  v1::ComputeDistanceFieldRequest request = FieldRequestOf(SlopeTravel(false, WalkerTable()));
  v1::TravelCost* travel = request.mutable_options()->mutable_travel();
  ASSERT_TRUE(ReadField(request).status.ok());

  // A bad row: its index.
  travel->mutable_speed_table(1)->set_speed_kmh(-1);
  auto [field, message] = field_error(request);
  EXPECT_EQ(field, "options.travel.speed_table[1]");
  EXPECT_TRUE(Contains(message, "-1")) << message;
  travel->mutable_speed_table(1)->set_speed_kmh(5.5);
  travel->mutable_speed_table(1)->set_slope_deg(-40);  // does not increase
  EXPECT_EQ(field_error(request).first, "options.travel.speed_table[1]");
  travel->mutable_speed_table(1)->set_slope_deg(-10);
  // Too few rows, or not covering the level.
  v1::TravelCost saved = *travel;
  while (travel->speed_table_size() > 1) travel->mutable_speed_table()->RemoveLast();
  EXPECT_EQ(field_error(request).first, "options.travel.speed_table");
  *travel = saved;
  travel->mutable_speed_table()->DeleteSubrange(0, 3);  // 10 and 35 degrees only
  EXPECT_EQ(field_error(request).first, "options.travel.speed_table");
  *travel = saved;
  // A table without the table model; a speed with a slope-dependent one.
  travel->set_speed_model(v1::SPEED_MODEL_TOBLER);
  EXPECT_EQ(field_error(request).first, "options.travel.speed_table");
  travel->clear_speed_table();
  ASSERT_TRUE(ReadField(request).status.ok());
  travel->set_speed_kmh(4);
  EXPECT_EQ(field_error(request).first, "options.travel.speed_kmh");
  travel->set_speed_kmh(0);
  // An unknown model.
  travel->set_speed_model(static_cast<v1::SpeedModel>(9));
  EXPECT_EQ(field_error(request).first, "options.travel.speed_model");
  // Paths name the row under their own options too.
  *travel = saved;
  travel->mutable_speed_table(1)->set_speed_kmh(0);
  v1::FindShortestPathRequest path;
  path.set_mesh("meshes/hills");
  path.mutable_from()->set_vertex(3);
  path.mutable_to()->set_vertex(40);
  *path.mutable_options() = request.options();
  v1::FindShortestPathResponse response;
  grpc::ClientContext context;
  grpc::Status status = stub_->FindShortestPath(&context, path, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(status), "options.travel.speed_table[1]") << status.error_message();
}

TEST_F(TravelServiceTest, ErrorsNameTheTravelField) {
  auto field_error = [&](const v1::ComputeDistanceFieldRequest& request) {
    Field got = ReadField(request);
    EXPECT_EQ(got.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << got.status.error_message();
    return std::make_pair(BadField(got.status), got.status.error_message());
  };
  v1::ComputeDistanceFieldRequest request = FieldRequestOf(Travel());
  v1::TravelCost* travel = request.mutable_options()->mutable_travel();

  travel->set_speed_kmh(0);
  EXPECT_EQ(field_error(request).first, "options.travel.speed_kmh");
  travel->set_speed_kmh(4);
  travel->set_epsilon(1.5);
  EXPECT_EQ(field_error(request).first, "options.travel.epsilon");
  travel->set_epsilon(0.05);
  travel->set_max_slope_deg(91);
  EXPECT_EQ(field_error(request).first, "options.travel.max_slope_deg");
  travel->set_max_slope_deg(0);

  // Weights: one per face, each > 0 (or +inf).
  travel->mutable_face_weights()->RemoveLast();
  auto [field, message] = field_error(request);
  EXPECT_EQ(field, "options.travel.face_weights");
  EXPECT_TRUE(Contains(message, std::to_string(faces_))) << message;
  travel->add_face_weights(1);
  travel->set_face_weights(7, -2);
  EXPECT_EQ(field_error(request).first, "options.travel.face_weights[7]");
  travel->set_face_weights(7, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(field_error(request).first, "options.travel.face_weights[7]");
  travel->set_face_weights(7, std::numeric_limits<double>::infinity());  // impassable: fine
  EXPECT_TRUE(ReadField(request).status.ok());
  // At most one of weights and friction polygons.
  travel->set_friction_geojson(R"({"type": "FeatureCollection", "features": []})");
  EXPECT_EQ(field_error(request).first, "options.travel.friction_geojson");
  travel->clear_friction_geojson();
  // lambda > 0 with a travel cost.
  request.mutable_options()->set_lambda(0.5);
  EXPECT_EQ(field_error(request).first, "options.travel");
  request.mutable_options()->set_lambda(0);

  // Directions have no travel-time version.
  request.set_want_directions(true);
  EXPECT_EQ(field_error(request).first, "options.travel");
  request.set_want_directions(false);
  {
    v1::EstimateDistancesRequest estimate;
    estimate.set_mesh("meshes/hills");
    estimate.add_sources()->set_vertex(3);
    estimate.add_points()->set_vertex(40);
    *estimate.mutable_options() = request.options();
    estimate.set_mode(v1::POINT_DISTANCE_MODE_EXACT);
    estimate.set_want_directions(true);
    v1::EstimateDistancesResponse response;
    grpc::ClientContext context;
    grpc::Status status = stub_->EstimateDistances(&context, estimate, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(BadField(status), "options.travel") << status.error_message();
    // The unfolding estimate reads metres.
    estimate.set_want_directions(false);
    estimate.set_mode(v1::POINT_DISTANCE_MODE_BOTH);
    grpc::ClientContext context2;
    status = stub_->EstimateDistances(&context2, estimate, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(BadField(status), "options.travel") << status.error_message();
  }
  // Nor has the geodesic Delaunay triangulation.
  {
    v1::ComputeDelaunayRequest delaunay;
    delaunay.set_mesh("meshes/hills");
    for (const SurfacePoint& p : Sites()) SurfacePointToProto(p, delaunay.add_sources());
    *delaunay.mutable_options() = request.options();
    std::vector<v1::ComputeDelaunayResponse> messages;
    grpc::Status status = ReadAll<v1::ComputeDelaunayResponse>(
        [&](grpc::ClientContext* c, const auto& r) { return stub_->ComputeDelaunay(c, r); },
        delaunay, &messages);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(BadField(status), "options.travel") << status.error_message();
  }
  // Paths name the weights too.
  {
    v1::FindShortestPathRequest path;
    path.set_mesh("meshes/hills");
    path.mutable_from()->set_vertex(3);
    path.mutable_to()->set_vertex(40);
    *path.mutable_options() = request.options();
    path.mutable_options()->mutable_travel()->set_face_weights(11, 0);
    v1::FindShortestPathResponse response;
    grpc::ClientContext context;
    grpc::Status status = stub_->FindShortestPath(&context, path, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(BadField(status), "options.travel.face_weights[11]") << status.error_message();
  }
}

TEST_F(TravelServiceTest, SteinerPointBudgetIsAFlag) {
  server_->Shutdown(absl::Now() + absl::Seconds(10));
  server_.reset();
  ServerOptions options;
  options.limits.max_steiner_points = 10;
  StartServer(options);
  ASSERT_TRUE(Upload(*stub_, off_, "hills").status.ok());
  Field got = ReadField(FieldRequestOf(Travel()));
  EXPECT_EQ(got.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(Contains(got.status.error_message(), "--max_steiner_points"))
      << got.status.error_message();
  EXPECT_EQ(Info(got.status).metadata().at("flag"), "max_steiner_points");
  // A plain field is not the weighted engine's: no Steiner points.
  EXPECT_TRUE(ReadField(FieldRequestOf(GeodesicOptions())).status.ok());
}

}  // namespace
}  // namespace geodex::server
