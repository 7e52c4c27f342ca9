// The C++ client library against an in-process geodexd: mesh resolution by file, id and alias,
// transparent re-upload when the server lost a mesh, retries on UNAVAILABLE, and results equal to
// core's.

#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "absl/time/clock.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geodex_client.h"
#include "geodex/mesh_id.h"
#include "geodex/samples.h"
#include "geodex/shortest_path.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using client::ClientOptions;
using client::GeodexClient;
using client::MeshRef;
using testing::GridOff;

class ClientTest : public testing::ServerFixture {
 protected:
  GeodexClient Client() {
    ClientOptions options;
    options.target = absl::StrCat("127.0.0.1:", server_->port());
    options.deadline_seconds = 60;
    return GeodexClient(options);
  }
  std::string WriteFile(const std::string& name, const std::string& text) {
    const std::string path = ::testing::TempDir() + "/" + name;
    std::ofstream(path) << text;
    return path;
  }
};

TEST_F(ClientTest, FileIsUploadedOnceByContentHashAndFieldsEqualCore) {
  StartServer();
  GeodexClient client = Client();
  const std::string off = GridOff(9, 7, true);
  const std::string path = WriteFile("client-hills.off", off);
  absl::StatusOr<MeshRef> first = client.ResolveMesh(path);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_TRUE(first->uploaded);
  EXPECT_EQ(first->id, ComputeMeshId(*ReadMeshFromBuffer(off, MeshFormat::kOff, "x.off")));
  absl::StatusOr<MeshRef> second = client.ResolveMesh(path);
  ASSERT_TRUE(second.ok());
  EXPECT_FALSE(second->uploaded);  // the server had it: no second upload
  EXPECT_EQ(server_->store().size(), 1u);

  absl::StatusOr<DistanceField> field =
      client.Field(*second, FieldQuery{{SurfacePoint::AtVertex(4)}, {}, false});
  ASSERT_TRUE(field.ok()) << field.status();
  DistanceField expected =
      *ComputeDistanceField(testing::BuildLocal(off), {SurfacePoint::AtVertex(4)});
  EXPECT_EQ(field->distance, expected.distance);
  EXPECT_EQ(field->source, expected.source);

  // By id and by alias.
  ASSERT_TRUE(client.Upload("x.off", off, "hills", first->id).ok());
  absl::StatusOr<MeshRef> by_alias = client.ResolveMesh("hills");
  ASSERT_TRUE(by_alias.ok());
  EXPECT_EQ(by_alias->id, first->id);
  absl::StatusOr<MeshRef> by_id = client.ResolveMesh(first->id);
  ASSERT_TRUE(by_id.ok());
  EXPECT_EQ(by_id->name, first->name);
  EXPECT_TRUE(absl::IsNotFound(client.ResolveMesh("no-such-mesh").status()));
}

TEST_F(ClientTest, SamplesResolveToTheServersBuiltInSamples) {
  ServerOptions options;
  options.samples = true;
  StartServer(options);
  GeodexClient client = Client();
  absl::StatusOr<MeshRef> terrain = client.ResolveMesh("sample:terrain");
  ASSERT_TRUE(terrain.ok()) << terrain.status();
  EXPECT_FALSE(terrain->uploaded);  // same generator, same content hash
  EXPECT_EQ(server_->store().size(), 3u);
}

TEST_F(ClientTest, AQueryForALostMeshReuploadsItOnce) {
  StartServer();
  GeodexClient client = Client();
  const std::string path = WriteFile("client-lost.off", GridOff(6, 6, true));
  absl::StatusOr<MeshRef> mesh = client.ResolveMesh(path);
  ASSERT_TRUE(mesh.ok());
  // The server loses the mesh (a restart elsewhere, a rebalanced gateway): the query still works.
  ASSERT_TRUE(server_->store().Delete(mesh->id).ok());
  absl::StatusOr<DistanceField> field =
      client.Field(*mesh, FieldQuery{{SurfacePoint::AtVertex(0)}, {}, false});
  ASSERT_TRUE(field.ok()) << field.status();
  EXPECT_EQ(client.reuploads(), 1);
  EXPECT_EQ(field->distance.size(), 49u);
  // A mesh known only by id cannot be re-uploaded: NOT_FOUND comes back.
  MeshRef by_id = *client.ResolveMesh(mesh->id);
  ASSERT_TRUE(server_->store().Delete(mesh->id).ok());
  EXPECT_TRUE(absl::IsNotFound(
      client.Field(by_id, FieldQuery{{SurfacePoint::AtVertex(0)}, {}, false}).status()));
}

// ClientOptions::max_snap rides on every query that takes points: the server refuses a position
// farther than that, naming it; without it the position is snapped.
TEST_F(ClientTest, MaxSnapIsCheckedByTheServerOnEveryQuery) {
  StartServer();
  const std::string path = WriteFile("client-snap.off", GridOff(6, 6, true));
  const SurfacePoint far = SurfacePoint::AtPosition(2, 2, 50);  // far above the grid
  GeodexClient snapping = Client();
  absl::StatusOr<MeshRef> mesh = snapping.ResolveMesh(path);
  ASSERT_TRUE(mesh.ok());
  PathQuery path_query;
  path_query.from = SurfacePoint::AtVertex(0);
  path_query.to = far;
  ASSERT_TRUE(snapping.ShortestPath(*mesh, path_query).ok());
  ClientOptions options;
  options.target = absl::StrCat("127.0.0.1:", server_->port());
  options.max_snap = 1;
  GeodexClient strict(options);
  absl::StatusOr<PathQueryResult> refused = strict.ShortestPath(*mesh, path_query);
  ASSERT_TRUE(absl::IsInvalidArgument(refused.status())) << refused.status();
  ASSERT_TRUE(client::FieldViolationOf(refused.status()).has_value());
  EXPECT_EQ(client::FieldViolationOf(refused.status())->field, "to.position");
  absl::StatusOr<DistanceField> field = strict.Field(*mesh, FieldQuery{{far}, {}, false});
  ASSERT_TRUE(absl::IsInvalidArgument(field.status())) << field.status();
  EXPECT_EQ(client::FieldViolationOf(field.status())->field, "sources[0].position");
  EXPECT_TRUE(strict.Locate(*mesh, {{2, 2, 50}}).status().code() ==
              absl::StatusCode::kInvalidArgument);
}

// A full queue (every worker busy, no room to wait) is worth retrying a moment later; a request
// over a limit is not. The worker is held by a task of the test's own, released after the first
// refusal, so the first attempt is refused for certain and a later one succeeds.
TEST_F(ClientTest, QueueFullIsRetriedWithBackoffButALimitIsNot) {
  ServerOptions options;
  options.pool_threads = 1;
  options.queue_capacity = 0;
  options.limits.max_targets = 1;
  StartServer(options);
  ClientOptions client_options;
  client_options.target = absl::StrCat("127.0.0.1:", server_->port());
  client_options.deadline_seconds = 60;
  client_options.max_attempts = 10;  // backoff 0.05 s doubling: up to 25 s in all
  client_options.initial_backoff_seconds = 0.05;
  GeodexClient client(client_options);
  const std::string off = GridOff(6, 6, true);
  MeshRef mesh = *client.ResolveMesh(WriteFile("client-queue.off", off));

  testing::Notification release;
  ASSERT_TRUE(server_->pool().TrySubmit([&release] { release.WaitForNotification(); }));
  for (int i = 0; i < 6000 && server_->pool().busy() == 0; ++i)
    absl::SleepFor(absl::Milliseconds(5));
  ASSERT_EQ(server_->pool().busy(), 1u);
  const uint64_t rejected_before = server_->pool().rejected();
  std::thread releaser([&] {
    for (int i = 0; i < 6000 && server_->pool().rejected() == rejected_before; ++i) {
      absl::SleepFor(absl::Milliseconds(5));
    }
    release.Notify();
  });
  const int retries_before = client.retries();
  absl::StatusOr<DistanceField> field =
      client.Field(mesh, FieldQuery{{SurfacePoint::AtVertex(3)}, {}, false});
  releaser.join();
  ASSERT_TRUE(field.ok()) << field.status();
  EXPECT_GE(client.retries() - retries_before, 1);
  EXPECT_GE(server_->pool().rejected(), rejected_before + 1);
  EXPECT_EQ(field->distance,
            ComputeDistanceField(testing::BuildLocal(off), {SurfacePoint::AtVertex(3)})->distance);

  // Two targets with --max_targets=1: RESOURCE_EXHAUSTED (reason LIMIT) at once, no retry.
  const int retries_mid = client.retries();
  absl::StatusOr<DistanceMatrix> matrix =
      client.Matrix(mesh, {{SurfacePoint::AtVertex(0)},
                           {SurfacePoint::AtVertex(1), SurfacePoint::AtVertex(2)},
                           MatrixOptions{}});
  EXPECT_EQ(matrix.status().code(), absl::StatusCode::kResourceExhausted) << matrix.status();
  EXPECT_EQ(client.retries(), retries_mid);
}

// A call's own CallOptions (deadline, max_snap) apply to that call alone.
TEST_F(ClientTest, PerCallOptionsApplyToThatCallAlone) {
  ServerOptions options;
  options.pool_threads = 1;
  options.queue_capacity = 4;
  StartServer(options);
  GeodexClient client = Client();  // deadline 60 s, any snap
  MeshRef mesh = *client.ResolveMesh(WriteFile("client-per-call.off", GridOff(8, 8, true)));
  PathQuery far_path;
  far_path.from = SurfacePoint::AtVertex(0);
  far_path.to = SurfacePoint::AtPosition(2, 2, 50);
  client::CallOptions strict;
  strict.max_snap = 1;
  absl::StatusOr<PathQueryResult> refused = client.ShortestPath(mesh, far_path, strict);
  ASSERT_TRUE(absl::IsInvalidArgument(refused.status())) << refused.status();
  EXPECT_EQ(client::FieldViolationOf(refused.status())->field, "to.position");
  ASSERT_TRUE(client.ShortestPath(mesh, far_path).ok());  // the client's own: any snap

  // The only worker held by the test: a field waits in the queue, and a call with a 0.2 s
  // deadline of its own is DEADLINE_EXCEEDED; once the worker is free, the next call (the
  // client's 60 s) answers.
  testing::Notification release;
  ASSERT_TRUE(server_->pool().TrySubmit([&release] { release.WaitForNotification(); }));
  for (int i = 0; i < 6000 && server_->pool().busy() == 0; ++i)
    absl::SleepFor(absl::Milliseconds(5));
  FieldQuery query{{SurfacePoint::AtVertex(5)}, {}, false};
  client::CallOptions hurried;
  hurried.deadline_seconds = 0.2;
  absl::Status hurried_status = client.Field(mesh, query, nullptr, hurried).status();
  EXPECT_TRUE(absl::IsDeadlineExceeded(hurried_status)) << hurried_status;
  release.Notify();
  EXPECT_EQ(client.deadline_seconds(), 60);
  absl::StatusOr<DistanceField> field = client.Field(mesh, query);
  EXPECT_TRUE(field.ok()) << field.status();
}

// Every result of a query that took 3D positions says how far each moved onto the surface, as
// LocatePoints does (0 for a point given on the surface).
TEST_F(ClientTest, ResultsCarryTheSnapDistances) {
  StartServer();
  GeodexClient client = Client();
  MeshRef mesh = *client.ResolveMesh(WriteFile("client-snaps.off", GridOff(8, 8, true)));
  const SurfacePoint above = SurfacePoint::AtPosition(2.5, 3.5, 20);
  absl::StatusOr<std::vector<LocatedPoint>> located = client.Locate(mesh, {above.position});
  ASSERT_TRUE(located.ok()) << located.status();
  const double snap = (*located)[0].distance;
  ASSERT_GT(snap, 10);

  PathQuery path_query;
  path_query.from = SurfacePoint::AtVertex(0);
  path_query.to = above;
  absl::StatusOr<PathQueryResult> path = client.ShortestPath(mesh, path_query);
  ASSERT_TRUE(path.ok()) << path.status();
  EXPECT_EQ(path->snap_distances, (std::vector<double>{0, snap}));

  absl::StatusOr<DistanceField> field = client.Field(mesh, FieldQuery{{above}, {}, false});
  ASSERT_TRUE(field.ok()) << field.status();
  EXPECT_EQ(field->snap_distances, std::vector<double>{snap});

  MatrixQuery matrix_query;
  matrix_query.sources = {above, SurfacePoint::AtVertex(3)};
  matrix_query.targets = {SurfacePoint::AtVertex(9)};
  absl::StatusOr<DistanceMatrix> matrix = client.Matrix(mesh, matrix_query);
  ASSERT_TRUE(matrix.ok()) << matrix.status();
  EXPECT_EQ(matrix->snap_distances, (std::vector<double>{snap, 0, 0}));

  PointQuery point_query;
  point_query.sources = {SurfacePoint::AtVertex(0)};
  point_query.points = {above};
  absl::StatusOr<client::PointDistances> at =
      client.DistancesAtPoints(mesh, point_query, client::PointDistanceMode::kExact);
  ASSERT_TRUE(at.ok()) << at.status();
  EXPECT_EQ(at->snap_distances, (std::vector<double>{0, snap}));
}

// The asynchronous form answers what the blocking one does, and a call waiting for a worker is
// cancelled at once (the worker is held by the test until after the cancel has answered).
TEST_F(ClientTest, AnAsyncCallAnswersAsTheBlockingOneAndCanBeCancelled) {
  ServerOptions options;
  options.pool_threads = 1;
  options.queue_capacity = 4;
  StartServer(options);
  GeodexClient client = Client();
  const std::string off = GridOff(8, 8, true);
  MeshRef mesh = *client.ResolveMesh(WriteFile("client-async.off", off));
  PathQuery path_query;
  path_query.from = SurfacePoint::AtVertex(0);
  path_query.to = SurfacePoint::AtVertex(80);
  absl::StatusOr<PathQueryResult> blocking = client.ShortestPath(mesh, path_query);
  ASSERT_TRUE(blocking.ok()) << blocking.status();
  client::AsyncCall<PathQueryResult> async = client.ShortestPathAsync(mesh, path_query);
  absl::StatusOr<PathQueryResult> answered = async.Get();
  ASSERT_TRUE(answered.ok()) << answered.status();
  EXPECT_EQ(answered->distance, blocking->distance);
  EXPECT_EQ(answered->path.points.size(), blocking->path.points.size());

  // The only worker held: a field (not cached: its own max_distance) waits in the queue.
  testing::Notification release;
  ASSERT_TRUE(server_->pool().TrySubmit([&release] { release.WaitForNotification(); }));
  for (int i = 0; i < 6000 && server_->pool().busy() == 0; ++i)
    absl::SleepFor(absl::Milliseconds(5));
  FieldQuery query{{SurfacePoint::AtVertex(7)}, {}, false};
  query.options.max_distance = 1e9 + 23;
  client::AsyncCall<DistanceField> waiting = client.FieldAsync(mesh, query);
  EXPECT_FALSE(waiting.Ready(0.3));  // still queued behind the held worker
  waiting.Cancel();
  ASSERT_TRUE(waiting.Ready(30)) << "the cancelled call did not answer";
  EXPECT_TRUE(absl::IsCancelled(waiting.Get().status()));
  release.Notify();

  // A Cancellation cancelled before the call: nothing is sent.
  auto cancelled = std::make_shared<client::Cancellation>();
  cancelled->Cancel();
  const int calls_before = client.calls();
  client::CallOptions call;
  call.cancel = cancelled;
  EXPECT_TRUE(absl::IsCancelled(client.ShortestPath(mesh, path_query, call).status()));
  EXPECT_EQ(client.calls(), calls_before);
}

// One client shared by threads calling at once: every answer is core's.
TEST_F(ClientTest, OneClientServesManyThreadsAtOnce) {
  StartServer();
  GeodexClient client = Client();
  const std::string off = GridOff(9, 9, true);
  const MeshRef mesh = *client.ResolveMesh(WriteFile("client-threads.off", off));
  const TriangleMesh local = testing::BuildLocal(off);
  constexpr int kThreads = 4, kCalls = 8;
  std::vector<std::thread> threads;
  std::vector<int> wrong(kThreads, 0);
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      MeshRef own = mesh;  // a MeshRef per thread (a re-upload may update it)
      for (int i = 0; i < kCalls; ++i) {
        PathQuery q;
        q.from = SurfacePoint::AtVertex(static_cast<uint32_t>(t));
        q.to = SurfacePoint::AtVertex(static_cast<uint32_t>(40 + 3 * i));
        absl::StatusOr<PathQueryResult> got = client.ShortestPath(own, q);
        absl::StatusOr<PathQueryResult> expected = ComputeShortestPath(local, q.from, q.to);
        if (!got.ok() || !expected.ok() || got->distance != expected->distance) ++wrong[t];
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(wrong, std::vector<int>(kThreads, 0));
  EXPECT_GE(client.calls(), kThreads * kCalls);
}

TEST(ClientRetryTest, UnavailableIsRetriedWithBackoffThenReported) {
  // A port nothing listens on (bound, then closed).
  int port = 0;
  {
    ServerOptions probe_options;
    probe_options.listen = "127.0.0.1:0";
    auto probe = GeodexServer::Start(probe_options);
    ASSERT_TRUE(probe.ok());
    port = (*probe)->port();
    (*probe)->Shutdown(absl::Now());
  }
  ClientOptions options;
  options.target = absl::StrCat("127.0.0.1:", port);
  options.initial_backoff_seconds = 0.01;
  options.reconnect_wait_seconds = 0.5;  // then UNAVAILABLE, whatever max_attempts says
  options.deadline_seconds = 10;
  GeodexClient client(options);
  absl::StatusOr<bool> health = client.Health();
  EXPECT_EQ(health.status().code(), absl::StatusCode::kUnavailable) << health.status();
  EXPECT_GE(client.calls(), 1);
  EXPECT_GE(client.retries(), 1);
}

TEST(ClientRetryTest, ACallMadeWhileTheServerRestartsSucceedsWithTheDefaults) {
  ServerOptions server_options;
  server_options.listen = "127.0.0.1:0";
  auto first = GeodexServer::Start(server_options);
  ASSERT_TRUE(first.ok()) << first.status();
  const int port = (*first)->port();
  (*first)->Shutdown(absl::Now());
  // Back on the same port 2 s later (longer than the 1.4 s the old 4 attempts spanned).
  server_options.listen = absl::StrCat("127.0.0.1:", port);
  std::unique_ptr<GeodexServer> again;
  std::thread restart([&] {
    absl::SleepFor(absl::Seconds(2));
    auto started = GeodexServer::Start(server_options);
    if (started.ok()) again = *std::move(started);
  });
  ClientOptions options;
  options.target = absl::StrCat("127.0.0.1:", port);
  options.deadline_seconds = 60;
  GeodexClient client(options);
  absl::StatusOr<bool> health = client.Health();
  restart.join();
  ASSERT_NE(again, nullptr) << "the server did not start again on port " << port;
  EXPECT_TRUE(health.ok()) << health.status();
  EXPECT_GE(client.retries(), 1);
  again->Shutdown(absl::Now());
}

}  // namespace
}  // namespace geodex::server
