// geodexd end to end: in-process servers on 127.0.0.1:0, clients with default limits.

#include <cstring>
#include <future>
#include <thread>

#include "absl/time/clock.h"
#include "geodex/distance_field.h"
#include "geodex/geodesic_solver.h"
#include "geodex/mesh_id.h"
#include "geodex/shortest_path.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/support/byte_buffer.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using testing::BuildLocal;
using testing::FieldRequest;
using testing::GridOff;
using testing::In;
using testing::ReadField;
using testing::Upload;

bool BitEqual(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

std::string LocalId(const std::string& off) {
  return ComputeMeshId(*ReadMeshFromBuffer(off, MeshFormat::kOff, "x.off"));
}

// Blocks every worker of `pool` until released; the destructor releases and waits until every
// blocking task has returned (so nothing it uses is destroyed under a worker).
class PoolBlocker {
 public:
  explicit PoolBlocker(ComputePool& pool) {
    const size_t n = pool.threads();
    for (size_t i = 0; i < n; ++i) {
      // A worker that just finished a call may not have counted itself idle yet: retry briefly.
      bool submitted = false;
      for (int attempt = 0; attempt < 10000 && !submitted; ++attempt) {
        submitted = pool.TrySubmit([this] {
          std::unique_lock<std::mutex> lock(mu_);
          ++running_;
          cv_.notify_all();
          cv_.wait(lock, [this] { return released_; });
          --running_;
          cv_.notify_all();
        });
        if (!submitted) absl::SleepFor(absl::Milliseconds(1));
      }
      EXPECT_TRUE(submitted);
      if (submitted) ++submitted_;
    }
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait(lock, [this] { return running_ == submitted_; });
  }
  ~PoolBlocker() {
    Release();
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait(lock, [this] { return running_ == 0; });
  }
  void Release() {
    std::lock_guard<std::mutex> lock(mu_);
    released_ = true;
    cv_.notify_all();
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  size_t submitted_ = 0, running_ = 0;
  bool released_ = false;
};

class ServiceTest : public testing::ServerFixture {};

TEST_F(ServiceTest, UploadGetListDelete) {
  StartServer();
  std::string off = GridOff(8, 6, true);
  testing::UploadResult up = Upload(*stub_, off, "terrain", /*chunk=*/100);
  ASSERT_TRUE(up.status.ok()) << up.status.error_message();
  EXPECT_EQ(up.mesh.name(), "meshes/" + LocalId(off));
  EXPECT_EQ(up.mesh.display_name(), "terrain");
  EXPECT_EQ(up.mesh.vertex_count(), 63u);
  EXPECT_EQ(up.mesh.face_count(), 96u);
  EXPECT_EQ(up.mesh.upload_bytes(), off.size());
  EXPECT_GT(up.mesh.memory_bytes(), 0u);
  EXPECT_GT(up.mesh.create_time().seconds(), 0);

  // Idempotent: same id, no second entry (one big chunk this time).
  testing::UploadResult again = Upload(*stub_, off, "", 1 << 20);
  ASSERT_TRUE(again.status.ok());
  EXPECT_EQ(again.mesh.name(), up.mesh.name());
  EXPECT_EQ(server_->store().size(), 1u);

  for (const std::string& name : {up.mesh.name(), std::string("meshes/terrain")}) {
    grpc::ClientContext context;
    context.set_deadline(In(30));
    v1::GetMeshRequest get;
    get.set_name(name);
    v1::Mesh mesh;
    ASSERT_TRUE(stub_->GetMesh(&context, get, &mesh).ok());
    EXPECT_EQ(mesh.name(), up.mesh.name());
  }

  // More meshes, then list them two per page.
  for (int cells = 2; cells <= 5; ++cells)
    ASSERT_TRUE(Upload(*stub_, GridOff(cells, 3, false)).status.ok());
  std::vector<std::string> names;
  std::string token;
  do {
    grpc::ClientContext context;
    context.set_deadline(In(30));
    v1::ListMeshesRequest list;
    list.set_page_size(2);
    list.set_page_token(token);
    v1::ListMeshesResponse response;
    ASSERT_TRUE(stub_->ListMeshes(&context, list, &response).ok());
    ASSERT_LE(response.meshes_size(), 2);
    for (const auto& m : response.meshes()) names.push_back(m.name());
    token = response.next_page_token();
  } while (!token.empty());
  EXPECT_EQ(names.size(), 5u);
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));

  {
    grpc::ClientContext context;
    v1::ListMeshesRequest list;
    list.set_page_token("garbage");
    v1::ListMeshesResponse response;
    EXPECT_EQ(stub_->ListMeshes(&context, list, &response).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
  }
  {
    grpc::ClientContext context;
    v1::DeleteMeshRequest del;
    del.set_name(up.mesh.name());
    v1::DeleteMeshResponse response;
    ASSERT_TRUE(stub_->DeleteMesh(&context, del, &response).ok());
  }
  {
    grpc::ClientContext context;
    v1::DeleteMeshRequest del;
    del.set_name(up.mesh.name());
    v1::DeleteMeshResponse response;
    EXPECT_EQ(stub_->DeleteMesh(&context, del, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    v1::GetMeshRequest get;
    get.set_name("meshes/terrain");
    v1::Mesh mesh;
    EXPECT_EQ(stub_->GetMesh(&context, get, &mesh).error_code(), grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    v1::GetMeshRequest get;
    get.set_name("terrain");
    v1::Mesh mesh;
    grpc::Status status = stub_->GetMesh(&context, get, &mesh);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(status.error_message().find("name"), std::string::npos);
  }
}

TEST_F(ServiceTest, UploadErrors) {
  ServerOptions options;
  options.limits.max_upload_bytes = 10'000;
  StartServer(options);
  EXPECT_EQ(Upload(*stub_, GridOff(40, 40, false)).status.error_code(),
            grpc::StatusCode::RESOURCE_EXHAUSTED);
  grpc::Status bad = Upload(*stub_, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").status;
  EXPECT_EQ(bad.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << bad.error_message();
  EXPECT_EQ(Upload(*stub_, GridOff(2, 2, false), "bad alias!").status.error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  // A client-computed id that does not match the upload.
  {
    grpc::ClientContext context;
    v1::Mesh mesh;
    auto writer = stub_->CreateMesh(&context, &mesh);
    v1::CreateMeshRequest request;
    request.mutable_metadata()->set_expected_mesh_id(std::string(64, 'b'));
    writer->Write(request);
    request.set_chunk(GridOff(2, 2, false));
    writer->Write(request);
    writer->WritesDone();
    grpc::Status s = writer->Finish();
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(s.error_message().find("expected_mesh_id"), std::string::npos) << s.error_message();
  }
  // A stream without metadata.
  grpc::ClientContext context;
  v1::Mesh mesh;
  auto writer = stub_->CreateMesh(&context, &mesh);
  v1::CreateMeshRequest request;
  request.set_chunk("OFF\n");
  writer->Write(request);
  writer->WritesDone();
  EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(ServiceTest, LargeMeshAndStreamedFieldEqualCoreBitForBit) {
  StartServer();
  // 385k vertices: an upload of ~14 MB and a field with labels of ~4.6 MB, both over 4 MiB.
  std::string off = GridOff(600, 640, false);
  ASSERT_GT(off.size(), size_t{4} << 20);
  testing::UploadResult up = Upload(*stub_, off);
  ASSERT_TRUE(up.status.ok()) << up.status.error_message();
  EXPECT_EQ(up.mesh.name(), "meshes/" + LocalId(off));

  // max_distance keeps the solve short (a full exact field on this flat grid takes minutes);
  // the field still has a value (+inf beyond the radius) for every vertex.
  v1::ComputeDistanceFieldRequest request = FieldRequest(up.mesh.name(), {0, 200000});
  request.set_want_stats(true);
  request.mutable_options()->set_max_distance(25);
  testing::FieldResult field = ReadField(*stub_, request);
  ASSERT_TRUE(field.status.ok()) << field.status.error_message();
  EXPECT_GT(field.messages, 1);
  EXPECT_GT(field.distances.size() * 12, size_t{4} << 20);
  EXPECT_GT(field.stats.windows_created(), 0u);

  TriangleMesh local = BuildLocal(off);
  GeodesicOptions options;
  options.max_distance = 25;
  DistanceField expected = *ComputeDistanceField(
      local, {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(200000)}, options);
  EXPECT_TRUE(std::isfinite(expected.distance[1]));
  EXPECT_TRUE(std::isinf(expected.distance.back()));
  EXPECT_TRUE(BitEqual(field.distances, expected.distance));
  EXPECT_EQ(field.labels, expected.source);

  // float32, no labels.
  request.set_value_type(v1::VALUE_TYPE_FLOAT32);
  request.set_omit_labels(true);
  testing::FieldResult f32 = ReadField(*stub_, request);
  ASSERT_TRUE(f32.status.ok()) << f32.status.error_message();
  ASSERT_EQ(f32.distances_f32.size(), expected.distance.size());
  EXPECT_TRUE(f32.labels.empty());
  for (size_t i = 0; i < expected.distance.size(); i += 997) {
    EXPECT_EQ(f32.distances_f32[i], static_cast<float>(expected.distance[i]));
  }
}

TEST_F(ServiceTest, FieldWithEdgeFaceAndPositionSourcesEqualsCore) {
  StartServer();
  std::string off = GridOff(20, 15, true);
  testing::UploadResult up = Upload(*stub_, off);
  ASSERT_TRUE(up.status.ok());
  TriangleMesh local = BuildLocal(off);

  v1::ComputeDistanceFieldRequest request;
  request.set_mesh(up.mesh.name());
  auto* e = request.add_sources()->mutable_edge();
  e->set_from(0);
  e->set_to(1);
  e->set_t(0.25);
  auto* f = request.add_sources()->mutable_face();
  f->set_face(100);
  f->set_b0(0.2);
  f->set_b1(0.3);
  f->set_b2(0.5);
  auto* p = request.add_sources()->mutable_position();
  p->set_x(15);
  p->set_y(3);
  p->set_z(5);
  request.mutable_options()->set_max_distance(6);
  testing::FieldResult field = ReadField(*stub_, request);
  ASSERT_TRUE(field.status.ok()) << field.status.error_message();

  SurfaceLocator locator(local);
  GeodesicOptions options;
  options.max_distance = 6;
  DistanceField expected = *ComputeDistanceField(
      local,
      {SurfacePoint::OnEdge(0, 1, 0.25), SurfacePoint::InFace(100, 0.2, 0.3, 0.5),
       locator.Locate({15, 3, 5})->point},
      options);
  EXPECT_TRUE(BitEqual(field.distances, expected.distance));
  EXPECT_EQ(field.labels, expected.source);
}

TEST_F(ServiceTest, ShortestPathEqualsCore) {
  StartServer();
  std::string off = GridOff(30, 20, true);
  testing::UploadResult up = Upload(*stub_, off, "hills");
  ASSERT_TRUE(up.status.ok());
  TriangleMesh local = BuildLocal(off);

  v1::FindShortestPathRequest request;
  request.set_mesh("meshes/hills");
  request.mutable_from()->set_vertex(3);
  request.mutable_to()->set_vertex(600);
  request.set_want_stats(true);
  grpc::ClientContext context;
  context.set_deadline(In(60));
  v1::FindShortestPathResponse response;
  grpc::Status status = stub_->FindShortestPath(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();

  PathQueryResult expected =
      *ComputeShortestPath(local, SurfacePoint::AtVertex(3), SurfacePoint::AtVertex(600));
  EXPECT_EQ(response.distance(), expected.distance);
  ASSERT_EQ(response.points_size(), static_cast<int>(expected.path.points.size()));
  for (int i = 0; i < response.points_size(); ++i) {
    EXPECT_EQ(response.points(i).position().x(), expected.path.points[i].position[0]);
    EXPECT_EQ(response.points(i).position().y(), expected.path.points[i].position[1]);
    EXPECT_EQ(response.points(i).position().z(), expected.path.points[i].position[2]);
    EXPECT_NE(response.points(i).where().point_case(), v1::SurfacePoint::POINT_NOT_SET);
  }
  EXPECT_GT(response.stats().windows_created(), 0u);
}

TEST_F(ServiceTest, BadInputNamesTheField) {
  StartServer();
  testing::UploadResult up = Upload(*stub_, GridOff(5, 5, true));
  ASSERT_TRUE(up.status.ok());

  auto field_error = [&](const v1::ComputeDistanceFieldRequest& request) {
    return ReadField(*stub_, request, 30).status;
  };
  grpc::Status s = field_error(FieldRequest("meshes/" + std::string(64, 'a'), {0}));
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(s.error_message().find("mesh"), std::string::npos);

  s = field_error(FieldRequest(up.mesh.name(), {0, 36}));
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("sources[1].vertex"), std::string::npos) << s.error_message();

  s = field_error(FieldRequest(up.mesh.name(), {}));
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("sources"), std::string::npos);

  v1::ComputeDistanceFieldRequest edge = FieldRequest(up.mesh.name(), {});
  auto* e = edge.add_sources()->mutable_edge();
  e->set_from(0);
  e->set_to(20);  // not an edge
  e->set_t(0.5);
  s = field_error(edge);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("sources[0].edge"), std::string::npos) << s.error_message();

  v1::ComputeDistanceFieldRequest lambda = FieldRequest(up.mesh.name(), {0});
  lambda.mutable_options()->set_lambda(-1);
  s = field_error(lambda);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("options.lambda"), std::string::npos);

  v1::FindShortestPathRequest path;
  path.set_mesh(up.mesh.name());
  path.mutable_from()->set_vertex(0);
  grpc::ClientContext context;
  v1::FindShortestPathResponse response;
  s = stub_->FindShortestPath(&context, path, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("to"), std::string::npos) << s.error_message();
}

TEST_F(ServiceTest, LimitsAnswerResourceExhausted) {
  ServerOptions options;
  options.limits.max_sources = 2;
  options.limits.max_output_values = 30;
  StartServer(options);
  testing::UploadResult small = Upload(*stub_, GridOff(3, 3, false));
  testing::UploadResult big = Upload(*stub_, GridOff(6, 6, false));
  ASSERT_TRUE(small.status.ok() && big.status.ok());
  grpc::Status s = ReadField(*stub_, FieldRequest(small.mesh.name(), {0, 1, 2}), 30).status;
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(s.error_message().find("max_sources"), std::string::npos);
  s = ReadField(*stub_, FieldRequest(big.mesh.name(), {0}), 30).status;
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(s.error_message().find("max_output_values"), std::string::npos);
}

TEST_F(ServiceTest, FullPoolAnswersResourceExhaustedAtOnce) {
  ServerOptions options;
  options.pool_threads = 1;
  options.queue_capacity = 0;
  StartServer(options);
  testing::UploadResult up = Upload(*stub_, GridOff(5, 5, true));
  ASSERT_TRUE(up.status.ok());
  {
    PoolBlocker blocker(server_->pool());
    grpc::Status s = ReadField(*stub_, FieldRequest(up.mesh.name(), {0}), 30).status;
    EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_NE(s.error_message().find("queue"), std::string::npos);
  }
  // Once the worker is free again calls succeed (it may take a moment to count itself idle).
  grpc::Status s;
  for (int attempt = 0; attempt < 1000; ++attempt) {
    s = ReadField(*stub_, FieldRequest(up.mesh.name(), {0}), 30).status;
    if (s.error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED) break;
    absl::SleepFor(absl::Milliseconds(5));
  }
  EXPECT_TRUE(s.ok()) << s.error_message();
}

TEST_F(ServiceTest, DeadlineExceededThenWorkerServesNextCall) {
  ServerOptions options;
  options.pool_threads = 1;
  options.queue_capacity = 4;
  StartServer(options);
  testing::UploadResult up = Upload(*stub_, GridOff(10, 10, true));
  ASSERT_TRUE(up.status.ok());
  v1::FindShortestPathRequest request;
  request.set_mesh(up.mesh.name());
  request.mutable_from()->set_vertex(0);
  request.mutable_to()->set_vertex(120);
  {
    PoolBlocker blocker(server_->pool());
    grpc::ClientContext context;
    context.set_deadline(In(0.3));
    v1::FindShortestPathResponse response;
    EXPECT_EQ(stub_->FindShortestPath(&context, request, &response).error_code(),
              grpc::StatusCode::DEADLINE_EXCEEDED);
  }
  grpc::ClientContext context;
  context.set_deadline(In(60));
  v1::FindShortestPathResponse response;
  grpc::Status s = stub_->FindShortestPath(&context, request, &response);
  EXPECT_TRUE(s.ok()) << s.error_message();
  EXPECT_GT(response.distance(), 0);
}

TEST_F(ServiceTest, DeadlineCancelsARunningSolve) {
  ServerOptions options;
  options.pool_threads = 1;
  StartServer(options);
  testing::UploadResult up = Upload(*stub_, GridOff(600, 640, true));
  ASSERT_TRUE(up.status.ok());
  // Short deadline on a long solve: the client sees DEADLINE_EXCEEDED whatever the server does;
  // the worker must come free again for the next (small) call.
  testing::FieldResult slow = ReadField(*stub_, FieldRequest(up.mesh.name(), {0}), 0.05);
  EXPECT_EQ(slow.status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  testing::UploadResult small = Upload(*stub_, GridOff(4, 4, true));
  ASSERT_TRUE(small.status.ok()) << small.status.error_message();
  EXPECT_TRUE(ReadField(*stub_, FieldRequest(small.mesh.name(), {0}), 60).status.ok());
}

TEST_F(ServiceTest, ConcurrentClientsGetIdenticalResults) {
  ServerOptions options;
  options.pool_threads = 2;
  options.queue_capacity = 64;
  StartServer(options);
  std::string off = GridOff(25, 25, true);
  testing::UploadResult up = Upload(*stub_, off);
  ASSERT_TRUE(up.status.ok());
  TriangleMesh local = BuildLocal(off);
  DistanceField expected = *ComputeDistanceField(local, {SurfacePoint::AtVertex(7)});

  constexpr int kClients = 6, kQueries = 5;
  std::vector<int> matches(kClients, 0);
  std::vector<std::thread> threads;
  for (int c = 0; c < kClients; ++c) {
    threads.emplace_back([&, c] {
      auto channel = grpc::CreateChannel(absl::StrCat("127.0.0.1:", server_->port()),
                                         grpc::InsecureChannelCredentials());
      auto stub = v1::Geodex::NewStub(channel);
      for (int q = 0; q < kQueries; ++q) {
        testing::FieldResult f = ReadField(*stub, FieldRequest(up.mesh.name(), {7}));
        if (f.status.ok() && BitEqual(f.distances, expected.distance) &&
            f.labels == expected.source) {
          ++matches[c];
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  for (int c = 0; c < kClients; ++c) EXPECT_EQ(matches[c], kQueries) << "client " << c;
}

// grpc.health.v1.Health/Check through the generic stub: the request is HealthCheckRequest{service}
// and SERVING is the response bytes 08 01.
grpc::Status HealthCheck(grpc::Channel& channel, const std::string& service, std::string* reply) {
  grpc::GenericStub stub(channel.shared_from_this());
  std::string request;
  if (!service.empty()) {
    request.push_back(0x0a);
    request.push_back(static_cast<char>(service.size()));
    request += service;
  }
  grpc::Slice slice(request);
  grpc::ByteBuffer in(&slice, 1), out;
  grpc::ClientContext context;
  context.set_deadline(In(10));
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &in, &out,
                 [&](grpc::Status s) { done.set_value(s); });
  grpc::Status status = done.get_future().get();
  std::vector<grpc::Slice> slices;
  if (status.ok() && out.Dump(&slices).ok()) {
    reply->clear();
    for (const auto& s : slices) reply->append(reinterpret_cast<const char*>(s.begin()), s.size());
  }
  return status;
}

TEST_F(ServiceTest, HealthAnswersWhileEveryWorkerIsBusy) {
  ServerOptions options;
  options.pool_threads = 2;
  options.queue_capacity = 8;
  StartServer(options);
  testing::UploadResult up = Upload(*stub_, GridOff(5, 5, true));
  ASSERT_TRUE(up.status.ok());
  PoolBlocker blocker(server_->pool());
  // Queue some queries behind the blocked workers too.
  std::vector<std::thread> waiting;
  for (int i = 0; i < 3; ++i) {
    waiting.emplace_back([&] { ReadField(*stub_, FieldRequest(up.mesh.name(), {0}), 60); });
  }
  for (const std::string service : {"", "geodex.v1.Geodex"}) {
    std::string reply;
    grpc::Status s = HealthCheck(*channel_, service, &reply);
    ASSERT_TRUE(s.ok()) << service << ": " << s.error_message();
    EXPECT_EQ(reply, std::string("\x08\x01", 2)) << service;
  }
  // Metadata calls do not need a worker either.
  grpc::ClientContext context;
  context.set_deadline(In(10));
  v1::ListMeshesResponse list;
  EXPECT_TRUE(stub_->ListMeshes(&context, v1::ListMeshesRequest(), &list).ok());
  blocker.Release();
  for (auto& t : waiting) t.join();
}

TEST_F(ServiceTest, EvictionUnderSmallBudget) {
  std::string a = GridOff(20, 20, true), b = GridOff(21, 20, true), c = GridOff(22, 20, true);
  ServerOptions options;
  StartServer(options);
  testing::UploadResult ua = Upload(*stub_, a);
  ASSERT_TRUE(ua.status.ok());
  // Restart with a budget that fits two such meshes, not three.
  uint64_t one = ua.mesh.memory_bytes();
  server_->Shutdown(absl::Now() + absl::Seconds(5));
  options.mesh_budget_bytes = 2 * one + one / 2;
  StartServer(options);
  ASSERT_TRUE(Upload(*stub_, a).status.ok());
  ASSERT_TRUE(Upload(*stub_, b).status.ok());
  ASSERT_TRUE(Upload(*stub_, c).status.ok());
  EXPECT_EQ(server_->store().size(), 2u);
  EXPECT_FALSE(server_->store().Contains(LocalId(a)));
  // A mesh larger than the whole budget: RESOURCE_EXHAUSTED naming the budget.
  grpc::Status s = Upload(*stub_, GridOff(60, 60, true)).status;
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(s.error_message().find("mesh_budget_bytes"), std::string::npos) << s.error_message();
}

}  // namespace
}  // namespace geodex::server
