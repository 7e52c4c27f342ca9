// The result cache: repeated fields, and paths from one source to many goals, reuse one solve.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "absl/time/clock.h"
#include "geodex/shortest_path.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using testing::FieldRequest;
using testing::GridOff;
using testing::In;
using testing::ReadField;
using testing::Upload;

class ResultCacheTest : public testing::ServerFixture {};

v1::FindShortestPathResponse Path(v1::Geodex::Stub& stub, uint32_t from, uint32_t to) {
  v1::FindShortestPathRequest request;
  request.set_mesh("meshes/hills");
  request.mutable_from()->set_vertex(from);
  request.mutable_to()->set_vertex(to);
  request.set_want_stats(true);
  grpc::ClientContext context;
  context.set_deadline(In(60));
  v1::FindShortestPathResponse response;
  grpc::Status status = stub.FindShortestPath(&context, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return response;
}

TEST_F(ResultCacheTest, RepeatedFieldIsServedFromTheCache) {
  StartServer();
  ASSERT_TRUE(Upload(*stub_, GridOff(20, 20, true), "hills").status.ok());
  v1::ComputeDistanceFieldRequest request = FieldRequest("meshes/hills", {0, 200});
  request.set_want_stats(true);
  testing::FieldResult first = ReadField(*stub_, request);
  testing::FieldResult second = ReadField(*stub_, request);
  ASSERT_TRUE(first.status.ok() && second.status.ok());
  EXPECT_FALSE(first.stats.cached());
  EXPECT_TRUE(second.stats.cached());
  EXPECT_EQ(first.distances, second.distances);
  EXPECT_EQ(first.labels, second.labels);
  EXPECT_EQ(server_->cache().hits(), 1u);
  EXPECT_EQ(server_->cache().entries(), 1u);
  EXPECT_GT(server_->cache().bytes(), 441u * 12);
  EXPECT_EQ(server_->service().counters().solves.load(), 1u);

  // Different options or sources are different entries; the isolines of the same sites reuse it.
  request.mutable_options()->set_max_distance(5);
  testing::FieldResult bounded = ReadField(*stub_, request);
  EXPECT_FALSE(bounded.stats.cached());
  v1::ComputeIsolinesRequest isolines;
  isolines.set_mesh("meshes/hills");
  isolines.add_sources()->set_vertex(0);
  isolines.add_sources()->set_vertex(200);
  isolines.set_count(4);
  isolines.set_want_stats(true);
  grpc::ClientContext context;
  auto reader = stub_->ComputeIsolines(&context, isolines);
  v1::ComputeIsolinesResponse response, last;
  while (reader->Read(&response)) last = response;
  ASSERT_TRUE(reader->Finish().ok());
  EXPECT_TRUE(last.stats().cached());
  EXPECT_EQ(server_->cache().hits(), 2u);
}

TEST_F(ResultCacheTest, PathsFromOneSourceReuseOneField) {
  StartServer();
  std::string off = GridOff(20, 20, true);
  testing::UploadResult up = Upload(*stub_, off, "hills");
  ASSERT_TRUE(up.status.ok());
  const std::string mesh_id = up.mesh.name().substr(std::string("meshes/").size());
  TriangleMesh local = testing::BuildLocal(off);
  // The whole field from vertex 5, for its size.
  v1::ComputeDistanceFieldRequest whole = FieldRequest("meshes/hills", {5});
  whole.set_want_stats(true);
  const uint64_t field_windows = ReadField(*stub_, whole).stats.windows_created();
  // From vertex 6 (no field cached): every path runs A* on its caller's clock, the second one
  // included (it only offers the source for a background field); once that field is in the
  // cache, paths are traced from it. Every answer is the exact path, however it was made.
  auto check = [&](uint32_t from, uint32_t to, const v1::FindShortestPathResponse& path) {
    PathQueryResult expected =
        *ComputeShortestPath(local, SurfacePoint::AtVertex(from), SurfacePoint::AtVertex(to));
    EXPECT_NEAR(path.distance(), expected.distance, 1e-12 * expected.distance) << to;
    ASSERT_GE(path.points_size(), 2);
    // The path runs from `from` to `to` whichever way it was computed.
    EXPECT_EQ(path.points(0).where().vertex(), from);
    EXPECT_EQ(path.points(path.points_size() - 1).where().vertex(), to);
    double length = 0;
    for (int k = 1; k < path.points_size(); ++k) {
      const auto& a = path.points(k - 1).position();
      const auto& b = path.points(k).position();
      length += std::hypot(a.x() - b.x(), a.y() - b.y(), a.z() - b.z());
    }
    EXPECT_NEAR(length, path.distance(), 1e-9 * path.distance());
  };
  for (uint32_t to : {27u, 48u}) {  // short goals: A* touches a small part of the field
    v1::FindShortestPathResponse path = Path(*stub_, 6, to);
    check(6, to, path);
    EXPECT_FALSE(path.stats().cached()) << to;
    EXPECT_LT(path.stats().windows_created(), field_windows / 2) << "not a whole field: " << to;
  }
  // The background solve lands (a generous bound; it runs at the lowest priority).
  const std::string key = FieldCacheKey(mesh_id, {SurfacePoint::AtVertex(6)}, GeodesicOptions{});
  for (int i = 0; i < 600 && !server_->cache().Contains(key); ++i) {
    absl::SleepFor(absl::Milliseconds(100));
  }
  ASSERT_TRUE(server_->cache().Contains(key));
  EXPECT_EQ(server_->service().counters().background_solves.load(), 1u);
  for (uint32_t to : {440u, 100u, 230u}) {
    v1::FindShortestPathResponse path = Path(*stub_, 6, to);
    check(6, to, path);
    EXPECT_TRUE(path.stats().cached()) << to;
  }
}

// With background solves off, a repeated path source keeps running A*: nothing is solved or
// cached behind the caller's back.
TEST_F(ResultCacheTest, WithoutBackgroundSolvesPathsStayAStar) {
  ServerOptions options;
  options.background_solves = false;
  StartServer(options);
  ASSERT_TRUE(Upload(*stub_, GridOff(20, 20, true), "hills").status.ok());
  for (uint32_t to : {27u, 48u, 440u}) EXPECT_FALSE(Path(*stub_, 6, to).stats().cached());
  EXPECT_EQ(server_->service().counters().background_solves.load(), 0u);
  EXPECT_EQ(server_->cache().entries(), 0u);
}

TEST_F(ResultCacheTest, ZeroBudgetDisablesTheCache) {
  ServerOptions options;
  options.result_cache_bytes = 0;
  StartServer(options);
  ASSERT_TRUE(Upload(*stub_, GridOff(10, 10, true), "hills").status.ok());
  v1::ComputeDistanceFieldRequest request = FieldRequest("meshes/hills", {0});
  request.set_want_stats(true);
  EXPECT_FALSE(ReadField(*stub_, request).stats.cached());
  EXPECT_FALSE(ReadField(*stub_, request).stats.cached());
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(Path(*stub_, 5, 90).stats().cached());
  EXPECT_EQ(server_->cache().entries(), 0u);
  EXPECT_EQ(server_->service().counters().solves.load(), 5u);
}

// Reads a whole matrix (values and stats) from ComputeDistanceMatrix.
struct MatrixResult {
  grpc::Status status;
  std::vector<double> values;
  v1::SolveStats stats;
};
MatrixResult ReadMatrix(v1::Geodex::Stub& stub, const std::vector<uint32_t>& sources,
                        const std::vector<uint32_t>& targets, uint32_t k_nearest = 0) {
  v1::ComputeDistanceMatrixRequest request;
  request.set_mesh("meshes/hills");
  for (uint32_t v : sources) request.add_sources()->set_vertex(v);
  for (uint32_t v : targets) request.add_targets()->set_vertex(v);
  request.set_k_nearest(k_nearest);
  request.set_want_stats(true);
  grpc::ClientContext context;
  context.set_deadline(In(60));
  auto reader = stub.ComputeDistanceMatrix(&context, request);
  MatrixResult out;
  v1::ComputeDistanceMatrixResponse response;
  while (reader->Read(&response)) {
    out.values.insert(out.values.end(), response.values_f64().begin(), response.values_f64().end());
    if (response.has_stats()) out.stats = response.stats();
  }
  out.status = reader->Finish();
  return out;
}

TEST_F(ResultCacheTest, RepeatedMatrixAndRowsFromCachedFieldsAreNotSolvedAgain) {
  StartServer();
  ASSERT_TRUE(Upload(*stub_, GridOff(20, 20, true), "hills").status.ok());
  const std::vector<uint32_t> sources = {3, 150, 400}, targets = {0, 77, 210, 440, 299};
  MatrixResult first = ReadMatrix(*stub_, sources, targets);
  ASSERT_TRUE(first.status.ok()) << first.status.error_message();
  EXPECT_FALSE(first.stats.cached());
  const uint64_t solves = server_->service().counters().solves.load();
  MatrixResult again = ReadMatrix(*stub_, sources, targets);
  ASSERT_TRUE(again.status.ok());
  EXPECT_TRUE(again.stats.cached());
  EXPECT_EQ(again.values, first.values);  // the same entry, bit for bit
  EXPECT_EQ(server_->service().counters().solves.load(), solves);

  // Fields of two of the sources are cached: a new matrix from them reads those rows and solves
  // only the third; with all three cached it solves nothing. The k_nearest rows keep exactly the
  // k smallest.
  std::vector<std::vector<double>> fields;
  for (uint32_t s : sources) {
    testing::FieldResult f = ReadField(*stub_, FieldRequest("meshes/hills", {s}));
    ASSERT_TRUE(f.status.ok());
    fields.push_back(f.distances);
  }
  const std::vector<uint32_t> other_targets = {1, 78, 211, 439};
  const uint64_t before = server_->service().counters().solves.load();
  MatrixResult from_fields = ReadMatrix(*stub_, sources, other_targets);
  ASSERT_TRUE(from_fields.status.ok()) << from_fields.status.error_message();
  EXPECT_TRUE(from_fields.stats.cached());
  EXPECT_EQ(server_->service().counters().solves.load(), before);
  for (size_t r = 0; r < sources.size(); ++r) {
    for (size_t c = 0; c < other_targets.size(); ++c) {
      EXPECT_EQ(from_fields.values[r * other_targets.size() + c], fields[r][other_targets[c]]);
    }
  }
  // The first matrix's rows were solved (targeted); read from the fields they agree to 1e-12.
  MatrixResult reread = ReadMatrix(*stub_, sources, {0, 77, 210, 440});
  ASSERT_TRUE(reread.status.ok());
  for (size_t r = 0; r < sources.size(); ++r) {
    for (size_t c = 0; c < 4; ++c) {
      const double solved = first.values[r * targets.size() + c];
      EXPECT_NEAR(reread.values[r * 4 + c], solved, 1e-12 * std::max(1.0, solved));
    }
  }
  MatrixResult nearest = ReadMatrix(*stub_, sources, other_targets, 2);
  ASSERT_TRUE(nearest.status.ok());
  for (size_t r = 0; r < sources.size(); ++r) {
    std::vector<double> row(from_fields.values.begin() + r * 4,
                            from_fields.values.begin() + r * 4 + 4);
    std::vector<double> kept;
    for (size_t c = 0; c < 4; ++c) {
      if (!std::isinf(nearest.values[r * 4 + c])) kept.push_back(nearest.values[r * 4 + c]);
    }
    std::sort(row.begin(), row.end());
    std::sort(kept.begin(), kept.end());
    EXPECT_EQ(kept, std::vector<double>(row.begin(), row.begin() + 2));
  }
  // A mixed request: one source without a cached field is solved, the others are read.
  MatrixResult mixed = ReadMatrix(*stub_, {3, 5, 400}, other_targets);
  ASSERT_TRUE(mixed.status.ok());
  EXPECT_FALSE(mixed.stats.cached());
  MatrixResult solved_row = ReadMatrix(*stub_, {5}, other_targets);
  for (size_t c = 0; c < other_targets.size(); ++c) {
    EXPECT_EQ(mixed.values[c], fields[0][other_targets[c]]);
    EXPECT_EQ(mixed.values[4 + c], solved_row.values[c]);
    EXPECT_EQ(mixed.values[8 + c], fields[2][other_targets[c]]);
  }
}

}  // namespace
}  // namespace geodex::server
