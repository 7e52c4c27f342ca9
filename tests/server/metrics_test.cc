// Observability: the Prometheus endpoint is scraped over HTTP, and every call gives one log line.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <sstream>

#include "absl/strings/str_cat.h"
#include "server_test_util.h"
#include "spdlog/sinks/ostream_sink.h"
#include "spdlog/spdlog.h"

namespace geodex::server {
namespace {

using testing::FieldRequest;
using testing::GridOff;
using testing::ReadField;
using testing::Upload;

// GET /metrics on 127.0.0.1:port with a plain socket (HTTP/1.0: the server closes when done).
std::string Scrape(int port) {
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  EXPECT_GE(fd, 0);
  timeval timeout{30, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::string request = "GET /metrics HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
  EXPECT_EQ(::write(fd, request.data(), request.size()), static_cast<ssize_t>(request.size()));
  std::string reply;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;) reply.append(buffer, n);
  ::close(fd);
  return reply;
}

// The value of the sample line that starts with `series` (name and labels), or -1.
double Sample(const std::string& text, const std::string& series) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(series + " ", 0) == 0) return std::stod(line.substr(series.size() + 1));
  }
  return -1;
}

class MetricsTest : public testing::ServerFixture {};

TEST_F(MetricsTest, ScrapeCountsRequestsCacheHitsAndWindows) {
  ServerOptions options;
  options.metrics_listen = "127.0.0.1:0";
  StartServer(options);
  ASSERT_GT(server_->metrics().port(), 0);
  ASSERT_TRUE(Upload(*stub_, GridOff(15, 15, true), "hills").status.ok());
  ASSERT_TRUE(ReadField(*stub_, FieldRequest("meshes/hills", {0})).status.ok());
  ASSERT_TRUE(ReadField(*stub_, FieldRequest("meshes/hills", {0})).status.ok());  // cache hit
  EXPECT_EQ(ReadField(*stub_, FieldRequest("meshes/hills", {999})).status.error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);

  // The status is recorded as the call finishes: allow the last one a moment to be counted.
  std::string text;
  const std::string field_ok =
      "geodex_requests_total{code=\"OK\",method=\"geodex.v1.Geodex/ComputeDistanceField\"}";
  for (int attempt = 0; attempt < 100; ++attempt) {
    text = Scrape(server_->metrics().port());
    if (Sample(text, field_ok) == 2) break;
    absl::SleepFor(absl::Milliseconds(50));
  }
  ASSERT_NE(text.find("200 OK"), std::string::npos) << text.substr(0, 200);
  EXPECT_EQ(Sample(text, field_ok), 2);
  EXPECT_EQ(Sample(text,
                   "geodex_requests_total{code=\"INVALID_ARGUMENT\",method=\"geodex.v1."
                   "Geodex/ComputeDistanceField\"}"),
            1);
  EXPECT_EQ(
      Sample(text, "geodex_requests_total{code=\"OK\",method=\"geodex.v1.Geodex/CreateMesh\"}"), 1);
  EXPECT_EQ(Sample(text,
                   "geodex_request_duration_seconds_count{method=\"geodex.v1.Geodex/"
                   "ComputeDistanceField\"}"),
            3);
  EXPECT_EQ(Sample(text, "geodex_result_cache_hits_total"), 1);
  EXPECT_GT(Sample(text, "geodex_result_cache_bytes"), 0);
  EXPECT_EQ(Sample(text, "geodex_solves_total"), 1);
  EXPECT_GT(Sample(text, "geodex_windows_processed_total"), 0);
  EXPECT_EQ(Sample(text, "geodex_mesh_store_meshes"), 1);
  EXPECT_EQ(Sample(text, "geodex_mesh_store_bytes"), server_->store().used_bytes());
  EXPECT_EQ(Sample(text, "geodex_compute_workers"), 2);
  EXPECT_EQ(Sample(text, "geodex_compute_queue_depth"), 0);
}

TEST_F(MetricsTest, OneLogLinePerCallWithMethodMeshSourcesStatusAndRequestId) {
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("test", sink));
  ServerOptions options;
  options.log_requests = true;
  StartServer(options);
  ASSERT_TRUE(Upload(*stub_, GridOff(5, 5, true), "tiny").status.ok());
  {
    grpc::ClientContext context;
    context.AddMetadata("x-request-id", "abc-123");
    auto reader = stub_->ComputeDistanceField(&context, FieldRequest("meshes/tiny", {0, 7}));
    v1::ComputeDistanceFieldResponse response;
    while (reader->Read(&response)) {
    }
    ASSERT_TRUE(reader->Finish().ok());
  }
  EXPECT_EQ(ReadField(*stub_, FieldRequest("meshes/none", {0})).status.error_code(),
            grpc::StatusCode::NOT_FOUND);
  server_->Shutdown(absl::Now() + absl::Seconds(10));  // every call logged
  spdlog::set_default_logger(previous);
  const std::string text = log.str();
  EXPECT_NE(text.find("request method=geodex.v1.Geodex/ComputeDistanceField mesh=meshes/tiny "
                      "sources=2 duration_ms="),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("status=OK request_id=abc-123"), std::string::npos) << text;
  EXPECT_NE(text.find("mesh=meshes/none sources=1"), std::string::npos) << text;
  EXPECT_NE(text.find("status=NOT_FOUND request_id=-"), std::string::npos) << text;
  EXPECT_NE(text.find("request method=geodex.v1.Geodex/CreateMesh mesh=meshes/"), std::string::npos)
      << text;
}

}  // namespace
}  // namespace geodex::server
