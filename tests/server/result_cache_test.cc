// The result cache: repeated fields, and paths from one source to many goals, reuse one solve.

#include <cmath>

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
  ASSERT_TRUE(Upload(*stub_, off, "hills").status.ok());
  TriangleMesh local = testing::BuildLocal(off);
  // 1st query from vertex 5: A*; 2nd: solves and caches the full field; 3rd..: traced from it.
  std::vector<uint32_t> goals = {440, 100, 230, 17, 399};
  for (size_t i = 0; i < goals.size(); ++i) {
    v1::FindShortestPathResponse path = Path(*stub_, 5, goals[i]);
    PathQueryResult expected =
        *ComputeShortestPath(local, SurfacePoint::AtVertex(5), SurfacePoint::AtVertex(goals[i]));
    EXPECT_NEAR(path.distance(), expected.distance, 1e-12 * expected.distance) << i;
    ASSERT_GE(path.points_size(), 2);
    // The path runs from `from` to `to` whichever way it was computed.
    EXPECT_EQ(path.points(0).where().vertex(), 5u);
    EXPECT_EQ(path.points(path.points_size() - 1).where().vertex(), goals[i]);
    double length = 0;
    for (int k = 1; k < path.points_size(); ++k) {
      const auto& a = path.points(k - 1).position();
      const auto& b = path.points(k).position();
      length += std::hypot(a.x() - b.x(), a.y() - b.y(), a.z() - b.z());
    }
    EXPECT_NEAR(length, path.distance(), 1e-9 * path.distance());
    EXPECT_EQ(path.stats().cached(), i >= 2) << i;
  }
  EXPECT_EQ(server_->service().counters().solves.load(), 2u);  // one A*, one field
  EXPECT_EQ(server_->cache().hits(), 3u);
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

}  // namespace
}  // namespace geodex::server
