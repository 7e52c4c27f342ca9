#pragma once

// Helpers of the geodexd tests: mesh generators (as OFF text), an in-process server on
// 127.0.0.1:0 with a client stub, chunked uploads and streamed distance fields.

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "geodex/mesh_io.h"
#include "geodex/triangle_mesh.h"
#include "geodex/v1/geodex.grpc.pb.h"
#include "geodex_server.h"
#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/byte_buffer.h"
#include "gtest/gtest.h"

namespace geodex::server::testing {

// A one-shot event on std::mutex (visible to ThreadSanitizer, unlike Debian's absl::Notification).
class Notification {
 public:
  void Notify() {
    std::lock_guard<std::mutex> lock(mu_);
    notified_ = true;
    cv_.notify_all();
  }
  void WaitForNotification() {
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait(lock, [this] { return notified_; });
  }
  bool HasBeenNotified() {
    std::lock_guard<std::mutex> lock(mu_);
    return notified_;
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  bool notified_ = false;
};

// A (cells_x x cells_y)-cell grid over [0, cells_x] x [0, cells_y] as OFF text; `bumpy` lifts it
// to a smooth terrain (so geodesics bend at saddles), otherwise it is flat.
inline std::string GridOff(int cells_x, int cells_y, bool bumpy) {
  std::string out;
  const int nx = cells_x + 1, ny = cells_y + 1;
  absl::StrAppend(&out, "OFF\n", nx * ny, " ", 2 * cells_x * cells_y, " 0\n");
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      double z = bumpy ? 0.8 * std::sin(0.7 * i) * std::cos(0.5 * j) : 0.0;
      absl::StrAppendFormat(&out, "%d %d %.17g\n", i, j, z);
    }
  }
  for (int j = 0; j < cells_y; ++j) {
    for (int i = 0; i < cells_x; ++i) {
      int a = j * nx + i, b = a + 1, c = a + nx + 1, d = a + nx;
      absl::StrAppend(&out, "3 ", a, " ", b, " ", c, "\n3 ", a, " ", c, " ", d, "\n");
    }
  }
  return out;
}

inline TriangleMesh BuildLocal(const std::string& off) {
  absl::StatusOr<MeshData> data = ReadMeshFromBuffer(off, MeshFormat::kOff, "local.off");
  EXPECT_TRUE(data.ok()) << data.status();
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*data);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return *std::move(mesh);
}

inline std::chrono::system_clock::time_point In(double seconds) {
  return std::chrono::system_clock::now() +
         std::chrono::microseconds(static_cast<int64_t>(seconds * 1e6));
}

struct UploadResult {
  grpc::Status status;
  v1::Mesh mesh;
};

inline UploadResult Upload(v1::Geodex::Stub& stub, const std::string& bytes,
                           const std::string& display_name = "", size_t chunk = 1 << 20,
                           bool pin = false) {
  UploadResult result;
  grpc::ClientContext context;
  // Generous: under ThreadSanitizer on a busy 2-core machine, building a 768k-face upload took
  // over 120 s once (48 s on an idle one). The bound only keeps a hung server from hanging tests.
  context.set_deadline(In(300));
  auto writer = stub.CreateMesh(&context, &result.mesh);
  v1::CreateMeshRequest request;
  request.mutable_metadata()->set_format(v1::MESH_FORMAT_OFF);
  request.mutable_metadata()->set_file_name("test.off");
  request.mutable_metadata()->set_display_name(display_name);
  request.mutable_metadata()->set_pin(pin);
  request.mutable_metadata()->set_total_bytes(bytes.size());
  bool ok = writer->Write(request);
  for (size_t offset = 0; ok && offset < bytes.size(); offset += chunk) {
    request.Clear();
    request.set_chunk(bytes.substr(offset, chunk));
    ok = writer->Write(request);
  }
  writer->WritesDone();
  result.status = writer->Finish();
  return result;
}

struct FieldResult {
  grpc::Status status;
  std::vector<double> distances;
  std::vector<float> distances_f32;
  std::vector<uint32_t> labels;
  int messages = 0;
  v1::SolveStats stats;
};

inline FieldResult ReadField(v1::Geodex::Stub& stub, const v1::ComputeDistanceFieldRequest& request,
                             double timeout_seconds = 120) {
  FieldResult result;
  grpc::ClientContext context;
  context.set_deadline(In(timeout_seconds));
  auto reader = stub.ComputeDistanceField(&context, request);
  v1::ComputeDistanceFieldResponse response;
  while (reader->Read(&response)) {
    EXPECT_EQ(response.offset(), std::max(result.distances.size(), result.distances_f32.size()));
    result.distances.insert(result.distances.end(), response.distances_f64().begin(),
                            response.distances_f64().end());
    result.distances_f32.insert(result.distances_f32.end(), response.distances_f32().begin(),
                                response.distances_f32().end());
    result.labels.insert(result.labels.end(), response.labels().begin(), response.labels().end());
    if (response.has_stats()) result.stats = response.stats();
    ++result.messages;
  }
  result.status = reader->Finish();
  return result;
}

inline v1::ComputeDistanceFieldRequest FieldRequest(const std::string& mesh_name,
                                                    std::vector<uint32_t> vertices) {
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh(mesh_name);
  for (uint32_t v : vertices) request.add_sources()->set_vertex(v);
  return request;
}

struct RawResult {
  grpc::Status status;
  std::vector<std::string> replies;
};

// One call of `method` through the generic stub (every gRPC call is a stream on the wire): sends
// each of `messages` as raw bytes, half-closes, reads every reply.
inline RawResult RawCall(const std::shared_ptr<grpc::Channel>& channel, const std::string& method,
                         const std::vector<std::string>& messages, const std::string& token = "") {
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  context.set_deadline(In(60));
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
  auto call = stub.PrepareCall(&context, method, &cq);
  auto wait = [&](intptr_t tag) {
    void* got = nullptr;
    bool ok = false;
    EXPECT_EQ(cq.AsyncNext(&got, &ok, In(60)), grpc::CompletionQueue::GOT_EVENT);
    EXPECT_EQ(got, reinterpret_cast<void*>(tag));
    return ok;
  };
  call->StartCall(reinterpret_cast<void*>(1));
  wait(1);
  for (const std::string& message : messages) {
    grpc::Slice slice(message);
    grpc::ByteBuffer buffer(&slice, 1);
    call->Write(buffer, reinterpret_cast<void*>(2));
    if (!wait(2)) break;  // the server already ended the call
  }
  call->WritesDone(reinterpret_cast<void*>(3));
  wait(3);
  RawResult result;
  for (;;) {
    grpc::ByteBuffer out;
    call->Read(&out, reinterpret_cast<void*>(4));
    if (!wait(4)) break;
    std::vector<grpc::Slice> slices;
    EXPECT_TRUE(out.Dump(&slices).ok());
    std::string reply;
    for (const auto& s : slices) reply.append(reinterpret_cast<const char*>(s.begin()), s.size());
    result.replies.push_back(reply);
  }
  call->Finish(&result.status, reinterpret_cast<void*>(5));
  wait(5);
  cq.Shutdown();
  void* tag;
  bool ok;
  while (cq.Next(&tag, &ok)) {
  }
  return result;
}

// An in-process server on 127.0.0.1:0 and a stub with default client limits.
// The field a google.rpc.BadRequest in the status's details names ("" when there is none).
inline std::string BadField(const grpc::Status& status) {
  google::rpc::Status details;
  google::rpc::BadRequest bad;
  EXPECT_TRUE(details.ParseFromString(status.error_details())) << status.error_message();
  for (const auto& any : details.details()) {
    if (any.UnpackTo(&bad) && bad.field_violations_size() > 0) {
      return bad.field_violations(0).field();
    }
  }
  return "";
}

inline bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class ServerFixture : public ::testing::Test {
 protected:
  void StartServer(ServerOptions options = {}) {
    options.listen = "127.0.0.1:0";
    if (options.pool_threads == 0) options.pool_threads = 2;
    auto server = GeodexServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
    channel_ = grpc::CreateChannel(absl::StrCat("127.0.0.1:", server_->port()),
                                   grpc::InsecureChannelCredentials());
    stub_ = v1::Geodex::NewStub(channel_);
  }
  void TearDown() override {
    if (server_) server_->Shutdown(absl::Now() + absl::Seconds(10));
  }

  std::unique_ptr<GeodexServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Geodex::Stub> stub_;
};

}  // namespace geodex::server::testing
