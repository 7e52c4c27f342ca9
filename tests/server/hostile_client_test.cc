// geodexd driven as a hostile or careless client would drive it, with raw bytes where a generated
// stub could not send them (issue 17; docs/reliability.md lists the cases). Each test is one of
// the failures reported against the proto by an independent client.

#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "absl/time/clock.h"
#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/support/byte_buffer.h"
#include "listen_address.h"
#include "server_test_util.h"
#include "util/gzip.h"

namespace geodex::server {
namespace {

using testing::FieldRequest;
using testing::GridOff;
using testing::In;
using testing::ReadField;
using testing::Upload;

using testing::RawCall;
using testing::RawResult;

std::string Metadata(const std::string& name, uint64_t total_bytes = 0,
                     v1::MeshFormat format = v1::MESH_FORMAT_OFF) {
  v1::CreateMeshRequest request;
  request.mutable_metadata()->set_format(format);
  request.mutable_metadata()->set_file_name("t.off");
  request.mutable_metadata()->set_display_name(name);
  request.mutable_metadata()->set_total_bytes(total_bytes);
  return request.SerializeAsString();
}

std::string Chunk(const std::string& bytes) {
  v1::CreateMeshRequest request;
  request.set_chunk(bytes);
  return request.SerializeAsString();
}

// Bytes that are no valid protobuf message: field 1, length-delimited, length 1000, 3 bytes follow.
const std::string kGarbage("\x0a\xe8\x07xyz", 6);

google::rpc::ErrorInfo Info(const grpc::Status& status) {
  google::rpc::Status details;
  google::rpc::ErrorInfo info;
  EXPECT_TRUE(details.ParseFromString(status.error_details())) << status.error_message();
  for (const auto& any : details.details()) {
    if (any.UnpackTo(&info)) return info;
  }
  ADD_FAILURE() << "no ErrorInfo in " << status.error_message();
  return info;
}

using testing::BadField;
using testing::Contains;

class HostileClientTest : public testing::ServerFixture {
 protected:
  size_t StoredMeshes() {
    grpc::ClientContext context;
    v1::ListMeshesRequest request;
    v1::ListMeshesResponse response;
    EXPECT_TRUE(stub_->ListMeshes(&context, request, &response).ok());
    return static_cast<size_t>(response.meshes_size());
  }
};

// 1. A message that fails to parse in the middle of an upload breaks the call: nothing is stored.
TEST_F(HostileClientTest, CorruptUploadStreamStoresNothing) {
  StartServer();
  const std::string off = GridOff(20, 20, true);
  const std::string first = off.substr(0, off.size() / 2), rest = off.substr(off.size() / 2);
  RawResult r = RawCall(channel_, "/geodex.v1.Geodex/CreateMesh",
                        {Metadata("half"), Chunk(first), kGarbage, Chunk(rest)});
  EXPECT_EQ(r.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << r.status.error_message();
  EXPECT_TRUE(Contains(r.status.error_message(), "message 3")) << r.status.error_message();
  EXPECT_TRUE(Contains(r.status.error_message(), "could not be parsed"));
  EXPECT_EQ(StoredMeshes(), 0u);

  // Garbage straight after the metadata says so (not "empty mesh").
  r = RawCall(channel_, "/geodex.v1.Geodex/CreateMesh", {Metadata("g"), kGarbage});
  EXPECT_EQ(r.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(Contains(r.status.error_message(), "message 2")) << r.status.error_message();

  // total_bytes must match what arrives, in both directions.
  r = RawCall(channel_, "/geodex.v1.Geodex/CreateMesh",
              {Metadata("short", 1000), Chunk(first), Chunk(rest)});
  EXPECT_EQ(r.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(r.status), "metadata.total_bytes") << r.status.error_message();
  r = RawCall(channel_, "/geodex.v1.Geodex/CreateMesh",
              {Metadata("long", off.size() + 10), Chunk(first), Chunk(rest)});
  EXPECT_EQ(r.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(r.status), "metadata.total_bytes") << r.status.error_message();
  EXPECT_EQ(StoredMeshes(), 0u);

  // The same stream, intact and with the right total, is stored.
  r = RawCall(channel_, "/geodex.v1.Geodex/CreateMesh",
              {Metadata("whole", off.size()), Chunk(first), Chunk(rest)});
  EXPECT_TRUE(r.status.ok()) << r.status.error_message();
  EXPECT_EQ(StoredMeshes(), 1u);
}

using testing_support::Gzip;

// 2. A gzip upload inflates at most to --max_upload_bytes.
TEST_F(HostileClientTest, GzipBombIsBoundedByTheUploadLimit) {
  ServerOptions options;
  options.limits.max_upload_bytes = 1'000'000;
  StartServer(options);
  const std::string bomb = Gzip("OFF\n" + std::string(50'000'000, ' '));
  ASSERT_LT(bomb.size(), options.limits.max_upload_bytes);
  RawResult r = RawCall(channel_, "/geodex.v1.Geodex/CreateMesh",
                        {Metadata("bomb", 0, v1::MESH_FORMAT_UNSPECIFIED), Chunk(bomb)});
  ASSERT_EQ(r.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
      << r.status.error_message();
  EXPECT_EQ(Info(r.status).reason(), "LIMIT");
  EXPECT_EQ(Info(r.status).metadata().at("flag"), "max_upload_bytes");
  EXPECT_EQ(StoredMeshes(), 0u);
}

// 3. A request that does not parse is INVALID_ARGUMENT saying so (not UNIMPLEMENTED), for unary,
// server-streaming and client-streaming methods.
TEST_F(HostileClientTest, UnparsableRequestsAreInvalidArgument) {
  StartServer();
  std::string deep;
  for (int i = 0; i < 5000; ++i) deep += '\x7b';  // start group, field 15
  for (int i = 0; i < 5000; ++i) deep += '\x7c';  // end group, field 15
  const std::vector<std::string> bad = {
      kGarbage,
      std::string("\x0a\x02\xff\xfe", 4),  // field 1 (a string) holding invalid UTF-8
      deep,
  };
  for (const GeodexService::MethodInfo& info : GeodexService::Methods()) {
    const std::string& method = info.name;
    for (size_t i = 0; i < bad.size(); ++i) {
      if (i == 1 && method == "ListMeshes") continue;  // its field 1 is an int: not a string
      RawResult r = RawCall(channel_, "/geodex.v1.Geodex/" + method, {bad[i]});
      EXPECT_EQ(r.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
          << method << " #" << i << ": " << r.status.error_message();
      EXPECT_TRUE(Contains(r.status.error_message(), "could not be parsed"))
          << method << " #" << i << ": " << r.status.error_message();
    }
  }
  RawResult r = RawCall(channel_, "/geodex.v1.Geodex/CreateMesh", {kGarbage});
  EXPECT_TRUE(Contains(r.status.error_message(), "message 1")) << r.status.error_message();
}

// With tokens on, the token is checked before any parsing.
TEST_F(HostileClientTest, TokenIsCheckedBeforeParsing) {
  const std::string dir = ::testing::TempDir() + "/hostile_tokens";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/tokens") << "secret-token\n";
  ServerOptions options;
  options.auth_token_file = dir + "/tokens";
  options.allow_plaintext_tokens = true;
  StartServer(options);
  for (const char* method : {"GetMesh", "ComputeDistanceField", "CreateMesh"}) {
    RawResult r = RawCall(channel_, std::string("/geodex.v1.Geodex/") + method, {kGarbage});
    EXPECT_EQ(r.status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << method;
    r = RawCall(channel_, std::string("/geodex.v1.Geodex/") + method, {kGarbage}, "secret-token");
    EXPECT_EQ(r.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << method;
  }
}

// 4. Echoed input is cut: the real status gets through the client's 8 KiB metadata limit.
TEST_F(HostileClientTest, HugeNamesAreCutInErrorMessages) {
  StartServer();
  const std::string huge(1 << 20, 'x');
  {
    grpc::ClientContext context;
    v1::GetMeshRequest request;
    request.set_name("meshes/" + huge);
    v1::Mesh response;
    grpc::Status s = stub_->GetMesh(&context, request, &response);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND) << s.error_message().substr(0, 200);
    EXPECT_LT(s.error_message().size(), 2100u);
    EXPECT_TRUE(Contains(s.error_message(), "cut: 1048583 bytes")) << s.error_message();
  }
  {
    grpc::ClientContext context;
    v1::GetMeshRequest request;
    request.set_name(huge);  // no "meshes/" prefix
    v1::Mesh response;
    grpc::Status s = stub_->GetMesh(&context, request, &response);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_LT(s.error_message().size(), 2100u);
  }
  testing::UploadResult up = Upload(*stub_, GridOff(3, 3, false), huge);
  EXPECT_EQ(up.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_LT(up.status.error_message().size(), 2100u);
  grpc::Status s = ReadField(*stub_, FieldRequest("meshes/" + huge, {0}), 30).status;
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
}

// 5. Every limit names its flag, in the message and in ErrorInfo.
TEST_F(HostileClientTest, VertexFaceAndWindowLimitsNameTheirFlags) {
  ServerOptions options;
  options.limits.max_vertices = 50;
  options.limits.max_windows = 10;
  StartServer(options);
  testing::UploadResult big = Upload(*stub_, GridOff(10, 10, true));
  ASSERT_EQ(big.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(Contains(big.status.error_message(), "--max_vertices")) << big.status.error_message();
  EXPECT_EQ(Info(big.status).reason(), "LIMIT");
  EXPECT_EQ(Info(big.status).metadata().at("flag"), "max_vertices");

  testing::UploadResult small = Upload(*stub_, GridOff(5, 5, true));
  ASSERT_TRUE(small.status.ok()) << small.status.error_message();
  grpc::Status s = ReadField(*stub_, FieldRequest(small.mesh.name(), {0}), 30).status;
  ASSERT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(Contains(s.error_message(), "--max_windows")) << s.error_message();
  EXPECT_EQ(Info(s).metadata().at("flag"), "max_windows");

  ServerOptions faces;
  faces.limits.max_faces = 10;
  server_->Shutdown(absl::Now());
  StartServer(faces);
  big = Upload(*stub_, GridOff(5, 5, true));
  ASSERT_EQ(big.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(Info(big.status).metadata().at("flag"), "max_faces") << big.status.error_message();
}

// 6 and 7. lambda out of range names options.lambda; an unknown MeshFormat is rejected.
TEST_F(HostileClientTest, LambdaAndUnknownEnumsNameTheirFields) {
  StartServer();
  testing::UploadResult up = Upload(*stub_, GridOff(5, 5, true));
  ASSERT_TRUE(up.status.ok());
  v1::ComputeDistanceFieldRequest request = FieldRequest(up.mesh.name(), {0});
  request.mutable_options()->set_lambda(2);
  grpc::Status s = ReadField(*stub_, request, 30).status;
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(s), "options.lambda") << s.error_message();
  EXPECT_TRUE(Contains(s.error_message(), "[0, 1]"));

  RawResult r =
      RawCall(channel_, "/geodex.v1.Geodex/CreateMesh",
              {Metadata("enum", 0, static_cast<v1::MeshFormat>(42)), Chunk(GridOff(3, 3, false))});
  EXPECT_EQ(r.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(r.status), "metadata.format") << r.status.error_message();
}

// 8. An unreachable target is FAILED_PRECONDITION with reason UNREACHABLE, never NOT_FOUND.
TEST_F(HostileClientTest, UnreachablePathIsFailedPrecondition) {
  StartServer();
  // Two triangles that share nothing.
  const std::string off =
      "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n5 5 0\n6 5 0\n5 6 0\n3 0 1 2\n3 3 4 5\n";
  testing::UploadResult up = Upload(*stub_, off);
  ASSERT_TRUE(up.status.ok()) << up.status.error_message();
  for (int repeat = 0; repeat < 3; ++repeat) {  // A*, then through the cached field
    grpc::ClientContext context;
    v1::FindShortestPathRequest request;
    request.set_mesh(up.mesh.name());
    request.mutable_from()->set_vertex(0);
    request.mutable_to()->set_vertex(4);
    v1::FindShortestPathResponse response;
    grpc::Status s = stub_->FindShortestPath(&context, request, &response);
    ASSERT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << s.error_message();
    EXPECT_EQ(Info(s).reason(), "UNREACHABLE");
  }
}

// 9. A stored mesh re-uploaded under a new name answers to both names.
TEST_F(HostileClientTest, ReuploadUnderANewNameAddsTheName) {
  StartServer();
  const std::string off = GridOff(4, 4, true);
  testing::UploadResult a = Upload(*stub_, off, "first");
  ASSERT_TRUE(a.status.ok());
  testing::UploadResult b = Upload(*stub_, off, "second");
  ASSERT_TRUE(b.status.ok()) << b.status.error_message();
  EXPECT_EQ(a.mesh.name(), b.mesh.name());
  for (const char* name : {"meshes/first", "meshes/second"}) {
    grpc::ClientContext context;
    v1::GetMeshRequest request;
    request.set_name(name);
    v1::Mesh mesh;
    grpc::Status s = stub_->GetMesh(&context, request, &mesh);
    ASSERT_TRUE(s.ok()) << name << ": " << s.error_message();
    EXPECT_EQ(mesh.name(), a.mesh.name());
    EXPECT_EQ(mesh.display_name(), "first");
    ASSERT_EQ(mesh.aliases_size(), 1);
    EXPECT_EQ(mesh.aliases(0), "second");
  }
  EXPECT_TRUE(ReadField(*stub_, FieldRequest("meshes/second", {0}), 30).status.ok());
}

// 10. Calls that need no solve do not wait for a solve worker.
TEST_F(HostileClientTest, CheapCallsDoNotWaitBehindSolves) {
  ServerOptions options;
  options.pool_threads = 1;
  StartServer(options);
  testing::UploadResult up = Upload(*stub_, GridOff(10, 10, true));
  ASSERT_TRUE(up.status.ok());
  ASSERT_TRUE(ReadField(*stub_, FieldRequest(up.mesh.name(), {0}), 30).status.ok());  // cached

  // The only solve worker is held until every cheap call below has answered.
  auto release = std::make_shared<testing::Notification>();
  auto holding = std::make_shared<testing::Notification>();
  ASSERT_TRUE(server_->pool().TrySubmit([release, holding] {
    holding->Notify();
    release->WaitForNotification();
  }));
  holding->WaitForNotification();

  // A field that needs a solve waits for the worker...
  auto uncached = std::async(std::launch::async, [&] {
    return ReadField(*stub_, FieldRequest(up.mesh.name(), {5}), 120).status;
  });
  // ...while the cached field, a trace from it, a locate and metadata answer now.
  EXPECT_TRUE(ReadField(*stub_, FieldRequest(up.mesh.name(), {0}), 60).status.ok());
  {
    grpc::ClientContext context;
    context.set_deadline(In(60));
    v1::LocatePointsRequest request;
    request.set_mesh(up.mesh.name());
    v1::Position* p = request.add_positions();
    p->set_x(2.2);
    p->set_y(3.1);
    p->set_z(1);
    v1::LocatePointsResponse response;
    EXPECT_TRUE(stub_->LocatePoints(&context, request, &response).ok());
  }
  {
    grpc::ClientContext context;
    context.set_deadline(In(60));
    v1::FindShortestPathRequest request;
    request.set_mesh(up.mesh.name());
    request.mutable_from()->set_vertex(0);
    request.mutable_to()->set_vertex(100);
    v1::FindShortestPathResponse response;
    grpc::Status s = stub_->FindShortestPath(&context, request, &response);
    EXPECT_TRUE(s.ok()) << s.error_message();
    EXPECT_GT(response.points_size(), 1);
  }
  EXPECT_EQ(uncached.wait_for(std::chrono::milliseconds(0)), std::future_status::timeout)
      << "the uncached field should still be waiting for the solve worker";
  release->Notify();
  EXPECT_TRUE(uncached.get().ok());
}

// 11. Addresses: a port is required, and a port in use says so, naming the flag.
TEST_F(HostileClientTest, ListenAddressesNeedAPortAndReportPortsInUse) {
  ServerOptions options;
  options.listen = "127.0.0.1";
  absl::Status s = ValidateServerOptions(options);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Contains(std::string(s.message()), "--listen=127.0.0.1")) << s;
  options.listen = "::1:50051";
  EXPECT_EQ(ValidateServerOptions(options).code(), absl::StatusCode::kInvalidArgument);
  options.listen = "[::1]:0";
  EXPECT_TRUE(ValidateServerOptions(options).ok());
  options.listen = "127.0.0.1:0";
  options.metrics_listen = "localhost";
  EXPECT_TRUE(Contains(std::string(ValidateServerOptions(options).message()), "--metrics_listen"));

  ServerOptions first;
  first.metrics_listen = "127.0.0.1:0";
  StartServer(first);
  ASSERT_GT(server_->metrics().port(), 0);
  ServerOptions second;
  second.listen = "127.0.0.1:0";
  second.metrics_listen = absl::StrCat("127.0.0.1:", server_->metrics().port());
  auto clash = GeodexServer::Start(second);
  ASSERT_EQ(clash.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_TRUE(Contains(std::string(clash.status().message()), "address in use")) << clash.status();
  EXPECT_TRUE(Contains(std::string(clash.status().message()), "--metrics_listen"));
  second.metrics_listen = "";
  second.listen = absl::StrCat("127.0.0.1:", server_->port());
  clash = GeodexServer::Start(second);
  ASSERT_FALSE(clash.ok());
  EXPECT_TRUE(Contains(std::string(clash.status().message()), "address in use")) << clash.status();
  EXPECT_TRUE(Contains(std::string(clash.status().message()), "--listen"));
}

// 12. An open health Watch stream ends at shutdown instead of holding it for the grace period.
TEST_F(HostileClientTest, ShutdownEndsHealthWatchStreams) {
  StartServer();
  grpc::GenericStub stub(channel_);
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  context.set_deadline(In(120));
  auto call = stub.PrepareCall(&context, "/grpc.health.v1.Health/Watch", &cq);
  auto wait = [&](intptr_t tag) {
    void* got = nullptr;
    bool ok = false;
    EXPECT_EQ(cq.AsyncNext(&got, &ok, In(120)), grpc::CompletionQueue::GOT_EVENT);
    EXPECT_EQ(got, reinterpret_cast<void*>(tag));
    return ok;
  };
  call->StartCall(reinterpret_cast<void*>(1));
  ASSERT_TRUE(wait(1));
  grpc::Slice empty("");  // HealthCheckRequest{service: ""}: no bytes
  grpc::ByteBuffer empty_request(&empty, 1);
  call->Write(empty_request, reinterpret_cast<void*>(2));
  ASSERT_TRUE(wait(2));
  call->WritesDone(reinterpret_cast<void*>(3));
  ASSERT_TRUE(wait(3));
  auto read = [&](std::string* reply) {
    grpc::ByteBuffer out;
    call->Read(&out, reinterpret_cast<void*>(4));
    if (!wait(4)) return false;
    std::vector<grpc::Slice> slices;
    EXPECT_TRUE(out.Dump(&slices).ok());
    reply->clear();
    for (const auto& s : slices) reply->append(reinterpret_cast<const char*>(s.begin()), s.size());
    return true;
  };
  std::string reply;
  ASSERT_TRUE(read(&reply));  // the watch is open: SERVING
  EXPECT_EQ(reply, std::string("\x08\x01", 2));

  const absl::Time deadline = absl::Now() + absl::Seconds(60);
  auto shutdown = std::async(std::launch::async, [&] { server_->Shutdown(deadline); });
  std::string last = reply;
  while (read(&reply)) last = reply;
  EXPECT_EQ(last, std::string("\x08\x02", 2));  // NOT_SERVING, then the stream ends
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(5));
  wait(5);
  EXPECT_TRUE(status.ok()) << status.error_message();
  shutdown.get();
  EXPECT_LT(absl::Now(), deadline - absl::Seconds(30)) << "shutdown waited for the Watch stream";
  cq.Shutdown();
  void* tag;
  bool ok;
  while (cq.Next(&tag, &ok)) {
  }
}

}  // namespace
}  // namespace geodex::server
