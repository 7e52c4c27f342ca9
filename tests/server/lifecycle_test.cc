// geodexd around the queries: rich error details, server reflection, and shutdown while calls are
// in flight (a queued call finishes within the grace period; a long solve is cancelled at its end).

#include <future>
#include <thread>

#include "absl/time/clock.h"
#include "google/protobuf/descriptor.h"
#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/support/byte_buffer.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using testing::FieldRequest;
using testing::GridOff;
using testing::In;
using testing::ReadField;
using testing::Upload;

class LifecycleTest : public testing::ServerFixture {};

google::rpc::Status Details(const grpc::Status& status) {
  google::rpc::Status details;
  EXPECT_TRUE(details.ParseFromString(status.error_details())) << "no google.rpc.Status details";
  EXPECT_EQ(details.code(), status.error_code());
  EXPECT_EQ(details.message(), status.error_message());
  return details;
}

TEST_F(LifecycleTest, ErrorsCarryBadRequestAndErrorInfoDetails) {
  ServerOptions options;
  options.limits.max_sources = 2;
  StartServer(options);
  testing::UploadResult up = Upload(*stub_, GridOff(5, 5, true));
  ASSERT_TRUE(up.status.ok());

  grpc::Status s = ReadField(*stub_, FieldRequest(up.mesh.name(), {0, 99}), 30).status;
  ASSERT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  google::rpc::Status details = Details(s);
  ASSERT_EQ(details.details_size(), 1);
  google::rpc::BadRequest bad_request;
  ASSERT_TRUE(details.details(0).UnpackTo(&bad_request));
  ASSERT_EQ(bad_request.field_violations_size(), 1);
  EXPECT_EQ(bad_request.field_violations(0).field(), "sources[1].vertex");
  EXPECT_NE(bad_request.field_violations(0).description().find("vertex 99 does not exist"),
            std::string::npos);

  s = ReadField(*stub_, FieldRequest(up.mesh.name(), {0, 1, 2}), 30).status;
  ASSERT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  details = Details(s);
  google::rpc::ErrorInfo info;
  ASSERT_EQ(details.details_size(), 1);
  ASSERT_TRUE(details.details(0).UnpackTo(&info));
  EXPECT_EQ(info.reason(), "LIMIT");
  EXPECT_EQ(info.domain(), "geodex.v1");
  EXPECT_EQ(info.metadata().at("flag"), "max_sources");

  // An unknown mesh: NOT_FOUND with ErrorInfo MESH_NOT_FOUND (what a client re-uploads on) and a
  // BadRequest naming the request field.
  s = ReadField(*stub_, FieldRequest("meshes/unknown", {0}), 30).status;
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  details = Details(s);
  ASSERT_EQ(details.details_size(), 2);
  ASSERT_TRUE(details.details(0).UnpackTo(&bad_request));
  EXPECT_EQ(bad_request.field_violations(0).field(), "mesh");
  ASSERT_TRUE(details.details(1).UnpackTo(&info));
  EXPECT_EQ(info.reason(), "MESH_NOT_FOUND");
}

// One exchange on grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo (a bidi stream);
// the request and response are raw protobuf bytes.
std::string ReflectionExchange(const std::shared_ptr<grpc::Channel>& channel,
                               const std::string& request) {
  testing::RawResult r = testing::RawCall(
      channel, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", {request});
  EXPECT_TRUE(r.status.ok()) << r.status.error_message();
  return r.replies.empty() ? std::string() : r.replies.front();
}

TEST_F(LifecycleTest, ReflectionListsTheServiceAndDescribesItsMethods) {
  StartServer();
  // ServerReflectionRequest{list_services: "*"} (field 7, a string).
  std::string list = ReflectionExchange(channel_, std::string("\x3a\x01*", 3));
  EXPECT_NE(list.find("geodex.v1.Geodex"), std::string::npos);
  EXPECT_NE(list.find("grpc.health.v1.Health"), std::string::npos);
  // ServerReflectionRequest{file_containing_symbol: "geodex.v1.Geodex"} (field 4): the reply holds
  // the serialized FileDescriptorProto of geodex.proto, with every method's name.
  const std::string symbol = "geodex.v1.Geodex";
  std::string file = ReflectionExchange(
      channel_, std::string("\x22", 1) + static_cast<char>(symbol.size()) + symbol);
  // Every method the service registers (its one table) is described, and the table covers every
  // method of the proto.
  const auto* service = google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(
      v1::Geodex::service_full_name());
  EXPECT_EQ(static_cast<size_t>(service->method_count()), GeodexService::Methods().size());
  for (const GeodexService::MethodInfo& method : GeodexService::Methods()) {
    EXPECT_NE(file.find(method.name), std::string::npos) << method.name;
    EXPECT_NE(service->FindMethodByName(method.name), nullptr) << method.name;
  }
}

TEST_F(LifecycleTest, ShutdownLetsAQueuedCallFinishWithinTheGracePeriod) {
  ServerOptions options;
  options.pool_threads = 1;
  StartServer(options);
  testing::UploadResult up = Upload(*stub_, GridOff(10, 10, true));
  ASSERT_TRUE(up.status.ok());

  // Shared with the task, so they live as long as it does.
  auto blocker = std::make_shared<testing::Notification>();
  auto blocking = std::make_shared<testing::Notification>();
  ASSERT_TRUE(server_->pool().TrySubmit([blocker, blocking] {
    blocking->Notify();
    blocker->WaitForNotification();
  }));
  blocking->WaitForNotification();
  // A field request waits in the queue behind the blocked worker.
  std::future<testing::FieldResult> call = std::async(
      std::launch::async, [&] { return ReadField(*stub_, FieldRequest(up.mesh.name(), {0}), 60); });
  for (int i = 0; i < 6000 && server_->pool().queued() == 0; ++i) {
    absl::SleepFor(absl::Milliseconds(5));
  }
  ASSERT_EQ(server_->pool().queued(), 1u);

  // Shutdown with a long grace period in another thread; release the worker afterwards: the call
  // that was in flight when shutdown began completes normally.
  std::thread shutdown([&] { server_->Shutdown(absl::Now() + absl::Seconds(60)); });
  absl::SleepFor(absl::Milliseconds(200));
  blocker->Notify();
  testing::FieldResult result = call.get();
  shutdown.join();
  EXPECT_TRUE(result.status.ok()) << result.status.error_message();
  EXPECT_EQ(result.distances.size(), 121u);
  EXPECT_EQ(result.distances[0], 0.0);
}

TEST_F(LifecycleTest, ShutdownCancelsALongSolveAtTheGraceDeadline) {
  ServerOptions options;
  options.pool_threads = 1;
  StartServer(options);
  // A flat 400 x 400 grid: an exact field takes far longer than the grace period.
  testing::UploadResult up = Upload(*stub_, GridOff(400, 400, false));
  ASSERT_TRUE(up.status.ok()) << up.status.error_message();
  std::future<testing::FieldResult> call = std::async(std::launch::async, [&] {
    return ReadField(*stub_, FieldRequest(up.mesh.name(), {80400}), 300);
  });
  for (int i = 0; i < 6000 && server_->pool().busy() == 0; ++i) {
    absl::SleepFor(absl::Milliseconds(5));
  }
  ASSERT_EQ(server_->pool().busy(), 1u);
  const absl::Time start = absl::Now();
  server_->Shutdown(absl::Now() + absl::Milliseconds(200));
  testing::FieldResult result = call.get();
  // Behaviour, not timing: the call ended without a result, and shutdown returned (well before
  // the solve could have finished on its own; the bound is generous).
  EXPECT_FALSE(result.status.ok());
  EXPECT_TRUE(result.distances.empty());
  EXPECT_LT(absl::Now() - start, absl::Seconds(120));
}

// Settings that cannot work are refused before anything starts, naming the flag; geodexd prints
// the message and exits 1. (--pool_threads=100000 used to abort with std::system_error.)
TEST(ServerOptionsTest, SettingsThatCannotWorkFailToStartNamingTheFlag) {
  ServerOptions defaults;
  defaults.listen = "127.0.0.1:0";
  EXPECT_TRUE(ValidateServerOptions(defaults).ok());
  struct Case {
    const char* flag;
    void (*set)(ServerOptions&);
  };
  const Case cases[] = {
      {"--pool_threads", [](ServerOptions& o) { o.pool_threads = 100000; }},
      {"--queue_capacity", [](ServerOptions& o) { o.queue_capacity = size_t{1} << 40; }},
      {"--mesh_budget_bytes", [](ServerOptions& o) { o.mesh_budget_bytes = 0; }},
      {"--max_receive_message_bytes", [](ServerOptions& o) { o.max_receive_message_bytes = 0; }},
      {"--max_receive_message_bytes", [](ServerOptions& o) { o.max_receive_message_bytes = -5; }},
      {"--max_upload_bytes", [](ServerOptions& o) { o.limits.max_upload_bytes = 0; }},
      {"--max_vertices", [](ServerOptions& o) { o.limits.max_vertices = 0; }},
      {"--max_faces", [](ServerOptions& o) { o.limits.max_faces = 0; }},
      {"--max_sources", [](ServerOptions& o) { o.limits.max_sources = 0; }},
      {"--max_targets", [](ServerOptions& o) { o.limits.max_targets = 0; }},
      {"--max_levels", [](ServerOptions& o) { o.limits.max_levels = 0; }},
      {"--max_output_values", [](ServerOptions& o) { o.limits.max_output_values = 0; }},
      {"--max_unary_response_bytes",
       [](ServerOptions& o) { o.limits.max_unary_response_bytes = 0; }},
      {"--stream_chunk_bytes", [](ServerOptions& o) { o.limits.stream_chunk_bytes = 0; }},
      {"--stream_chunk_bytes", [](ServerOptions& o) { o.limits.stream_chunk_bytes = 64u << 20; }},
  };
  for (const Case& c : cases) {
    ServerOptions options = defaults;
    c.set(options);
    absl::StatusOr<std::unique_ptr<GeodexServer>> server = GeodexServer::Start(options);
    EXPECT_EQ(server.status().code(), absl::StatusCode::kInvalidArgument) << c.flag;
    EXPECT_NE(server.status().message().find(c.flag), std::string::npos) << server.status();
  }
}

}  // namespace
}  // namespace geodex::server
