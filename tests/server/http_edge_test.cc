// geodexd's HTTP/JSON port (server/http_edge.h, http_transcode.h) against the gRPC answers of the
// same server: routes, uploads, assembled and NDJSON streams, files, error mapping, deadlines,
// tokens, Host and CORS checks. A small HTTP/1.1 client over a socket (Connection: close).

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "gdal_priv.h"
#include "google/protobuf/util/json_util.h"
#include "http_transcode.h"
#include "ogr_spatialref.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

namespace fs = std::filesystem;
using testing::Contains;

struct HttpReply {
  int status = 0;
  std::map<std::string, std::string> headers;  // lowercase names
  std::string body;
};

// One request on a fresh connection; the reply read to EOF (chunked bodies decoded).
HttpReply Http(int port, const std::string& method, const std::string& target,
               const std::string& body = "", std::map<std::string, std::string> headers = {}) {
  HttpReply reply;
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    close(fd);
    return reply;
  }
  if (headers.count("Host") == 0) headers["Host"] = absl::StrCat("127.0.0.1:", port);
  std::string request = absl::StrCat(method, " ", target, " HTTP/1.1\r\nConnection: close\r\n");
  for (const auto& [name, value] : headers) absl::StrAppend(&request, name, ": ", value, "\r\n");
  absl::StrAppend(&request, "Content-Length: ", body.size(), "\r\n\r\n", body);
  for (size_t sent = 0; sent < request.size();) {
    const ssize_t n = send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  std::string raw;
  char buffer[65536];
  for (ssize_t n; (n = recv(fd, buffer, sizeof buffer, 0)) > 0;) raw.append(buffer, n);
  close(fd);
  const size_t head_end = raw.find("\r\n\r\n");
  if (head_end == std::string::npos) return reply;
  std::vector<std::string> lines = absl::StrSplit(raw.substr(0, head_end), "\r\n");
  std::vector<std::string> status_line = absl::StrSplit(lines[0], ' ');
  if (status_line.size() < 2 || !absl::SimpleAtoi(status_line[1], &reply.status)) return reply;
  for (size_t i = 1; i < lines.size(); ++i) {
    const size_t colon = lines[i].find(':');
    if (colon == std::string::npos) continue;
    reply.headers[absl::AsciiStrToLower(lines[i].substr(0, colon))] =
        std::string(absl::StripAsciiWhitespace(lines[i].substr(colon + 1)));
  }
  std::string rest = raw.substr(head_end + 4);
  if (reply.headers["transfer-encoding"] == "chunked") {
    size_t at = 0;
    for (;;) {
      const size_t eol = rest.find("\r\n", at);
      if (eol == std::string::npos) break;
      size_t size = 0;
      if (!absl::SimpleHexAtoi(rest.substr(at, eol - at), &size) || size == 0) break;
      reply.body += rest.substr(eol + 2, size);
      at = eol + 2 + size + 2;
    }
  } else {
    reply.body = rest;
  }
  return reply;
}

template <typename Message>
Message FromJson(const std::string& json) {
  Message message;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &message);
  EXPECT_TRUE(status.ok()) << status.ToString() << "\n" << json.substr(0, 500);
  return message;
}

const std::map<std::string, std::string> kJson = {{"Content-Type", "application/json"}};

class HttpEdgeTest : public testing::ServerFixture {
 protected:
  void SetUp() override {
    GDALAllRegister();
    dir_ = fs::path(::testing::TempDir()) /
           absl::StrCat("geodex-http-", ::testing::UnitTest::GetInstance()->random_seed(), "-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // Rolling hills in UTM 33N, 10 m cells.
    const std::string tif = (dir_ / "hills.tif").string();
    GDALDataset* ds = GetGDALDriverManager()->GetDriverByName("GTiff")->Create(
        tif.c_str(), 40, 30, 1, GDT_Float32, nullptr);
    double gt[6] = {500000, 10, 0, 5000000, 0, -10};
    ds->SetGeoTransform(gt);
    OGRSpatialReference srs;
    srs.importFromEPSG(32633);
    ds->SetSpatialRef(&srs);
    std::vector<float> cells(40 * 30);
    for (int j = 0; j < 30; ++j) {
      for (int i = 0; i < 40; ++i) cells[j * 40 + i] = 15 * std::sin(i / 6.0) * std::cos(j / 5.0);
    }
    EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, 40, 30, cells.data(), 40, 30,
                                             GDT_Float32, 0, 0),
              CE_None);
    GDALClose(ds);
    std::ifstream in(tif, std::ios::binary);
    dem_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  void TearDown() override {
    testing::ServerFixture::TearDown();
    server_.reset();
    fs::remove_all(dir_);
  }
  void StartHttp(ServerOptions options = {}) {
    options.http.listen = "127.0.0.1:0";
    StartServer(options);
    port_ = server_->http_port();
    ASSERT_GT(port_, 0);
  }
  // Uploads the DEM over HTTP as "hills" (step 1); returns its mesh resource.
  v1::Mesh UploadHills() {
    HttpReply reply =
        Http(port_, "POST", "/v1/meshes?display_name=hills&format=MESH_FORMAT_GEOTIFF&dem.step=1",
             dem_, {{"Content-Type", "image/tiff"}});
    EXPECT_EQ(reply.status, 200) << reply.body;
    return FromJson<v1::Mesh>(reply.body);
  }

  fs::path dir_;
  std::string dem_;
  int port_ = 0;
};

TEST_F(HttpEdgeTest, ListsAnUploadedDemAndFindsThePathTheGrpcCallFinds) {
  ServerOptions options;
  options.replica_name = "replica-7";
  StartHttp(options);
  const v1::Mesh uploaded = UploadHills();
  EXPECT_TRUE(uploaded.has_terrain());
  EXPECT_EQ(uploaded.display_name(), "hills");

  HttpReply list = Http(port_, "GET", "/v1/meshes");
  ASSERT_EQ(list.status, 200) << list.body;
  EXPECT_EQ(list.headers["content-type"], "application/json");
  const auto listed = FromJson<v1::ListMeshesResponse>(list.body);
  bool found = false;
  for (const v1::Mesh& mesh : listed.meshes()) found |= mesh.name() == uploaded.name();
  EXPECT_TRUE(found) << list.body.substr(0, 300);

  const std::string body =
      R"({"from": {"mapPoint": {"x": 500055, "y": 4999945}}, "to": {"mapPoint": {"x": 500342, "y": 4999731}}})";
  HttpReply path = Http(port_, "POST", "/v1/meshes/hills:findShortestPath", body, kJson);
  ASSERT_EQ(path.status, 200) << path.body;
  const auto over_http = FromJson<v1::FindShortestPathResponse>(path.body);
  EXPECT_EQ(path.headers["x-geodex-replica"], "replica-7");  // which replica answered
  // A unit suffix reads as written (json_name), not lengthM.
  EXPECT_TRUE(Contains(path.body, "\"length_m\":")) << path.body.substr(0, 200);
  EXPECT_FALSE(Contains(path.body, "lengthM"));

  v1::FindShortestPathRequest request = FromJson<v1::FindShortestPathRequest>(body);
  request.set_mesh("meshes/hills");
  v1::FindShortestPathResponse over_grpc;
  grpc::ClientContext context;
  ASSERT_TRUE(stub_->FindShortestPath(&context, request, &over_grpc).ok());
  EXPECT_GT(over_grpc.distance(), 300);
  EXPECT_NEAR(over_http.distance(), over_grpc.distance(), 1e-12);
  EXPECT_EQ(over_http.points_size(), over_grpc.points_size());

  // The mesh by id too, percent-encoded or not; and GET of one mesh.
  const std::string id = uploaded.name().substr(7);
  HttpReply by_id =
      Http(port_, "POST", absl::StrCat("/v1/meshes/", id, ":findShortestPath"), body, kJson);
  EXPECT_EQ(FromJson<v1::FindShortestPathResponse>(by_id.body).distance(), over_http.distance());
  HttpReply get = Http(port_, "GET", "/v1/meshes/h%69lls");
  ASSERT_EQ(get.status, 200) << get.body;
  EXPECT_EQ(FromJson<v1::Mesh>(get.body).name(), uploaded.name());
}

TEST_F(HttpEdgeTest, ErrorsAreGoogleRpcStatusJsonWithTheirHttpCodes) {
  StartHttp();
  UploadHills();
  auto error_of = [](const HttpReply& reply) { return FromJson<google::rpc::Status>(reply.body); };

  HttpReply malformed =
      Http(port_, "POST", "/v1/meshes/hills:findShortestPath", R"({"from": )", kJson);
  EXPECT_EQ(malformed.status, 400);
  EXPECT_EQ(error_of(malformed).code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(Contains(error_of(malformed).message(), "body")) << malformed.body;

  HttpReply unknown_field =
      Http(port_, "POST", "/v1/meshes/hills:findShortestPath", R"({"form": {}})", kJson);
  EXPECT_EQ(unknown_field.status, 400);
  EXPECT_TRUE(Contains(error_of(unknown_field).message(), "form")) << unknown_field.body;

  HttpReply unknown_mesh = Http(port_, "POST", "/v1/meshes/nosuch:findShortestPath",
                                R"({"from": {"vertex": 0}, "to": {"vertex": 1}})", kJson);
  EXPECT_EQ(unknown_mesh.status, 404);
  const google::rpc::Status not_found = error_of(unknown_mesh);
  EXPECT_EQ(not_found.code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(Contains(not_found.message(), "nosuch"));
  bool mesh_not_found = false;  // the same structured details as the gRPC answer
  for (const auto& any : not_found.details()) {
    google::rpc::ErrorInfo info;
    if (any.UnpackTo(&info)) mesh_not_found |= info.reason() == "MESH_NOT_FOUND";
  }
  EXPECT_TRUE(mesh_not_found) << unknown_mesh.body;

  // A field error names the field, as over gRPC (BadRequest).
  HttpReply bad_vertex = Http(port_, "POST", "/v1/meshes/hills:findShortestPath",
                              R"({"from": {"vertex": 99999999}, "to": {"vertex": 1}})", kJson);
  EXPECT_EQ(bad_vertex.status, 400);
  EXPECT_TRUE(Contains(error_of(bad_vertex).message(), "from")) << bad_vertex.body;

  // Unreachable is FAILED_PRECONDITION: 400 by the convention.
  HttpReply far = Http(
      port_, "POST", "/v1/meshes/hills:findShortestPath",
      R"({"from": {"vertex": 0}, "to": {"vertex": 1199}, "options": {"maxDistance": 1}})", kJson);
  EXPECT_EQ(far.status, 400) << far.body;
  EXPECT_EQ(error_of(far).code(), grpc::StatusCode::FAILED_PRECONDITION);

  EXPECT_EQ(Http(port_, "GET", "/v2/meshes").status, 404);
  EXPECT_EQ(Http(port_, "POST", "/v1/meshes/hills:noSuchMethod", "{}", kJson).status, 404);
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes/hills:findShortestPath").status, 405);
  EXPECT_EQ(Http(port_, "PUT", "/v1/meshes").status, 405);
  // Media types: a form or text/plain body (what a cross-site page can post) is refused.
  EXPECT_EQ(Http(port_, "POST", "/v1/meshes/hills:findShortestPath", "{}",
                 {{"Content-Type", "text/plain"}})
                .status,
            415);
  EXPECT_EQ(Http(port_, "POST", "/v1/meshes", dem_,
                 {{"Content-Type", "application/x-www-form-urlencoded"}})
                .status,
            415);
  // Query parameters: unknown ones and JSON routes' are refused, naming them.
  HttpReply bogus = Http(port_, "GET", "/v1/meshes?bogus=1");
  EXPECT_EQ(bogus.status, 400);
  EXPECT_TRUE(Contains(error_of(bogus).message(), "bogus"));
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes?pageSize=2").status, 200);
  // A mesh in the body that is not the path's.
  HttpReply two_meshes =
      Http(port_, "POST", "/v1/meshes/hills:locatePoints", R"({"mesh": "meshes/other"})", kJson);
  EXPECT_EQ(two_meshes.status, 400);
}

TEST_F(HttpEdgeTest, StreamsAreAssembledOrSentAsNdjsonAndFilesComeWhole) {
  ServerOptions options;
  options.limits.stream_chunk_bytes = 1024;  // many messages per answer
  StartHttp(options);
  UploadHills();
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh("meshes/hills");
  request.add_sources()->set_vertex(17);
  const testing::FieldResult grpc_field = testing::ReadField(*stub_, request);
  ASSERT_TRUE(grpc_field.status.ok());
  ASSERT_GT(grpc_field.messages, 3);

  const std::string body = R"({"sources": [{"vertex": 17}]})";
  HttpReply whole = Http(port_, "POST", "/v1/meshes/hills:computeDistanceField", body, kJson);
  ASSERT_EQ(whole.status, 200) << whole.body.substr(0, 300);
  const auto field = FromJson<v1::ComputeDistanceFieldResponse>(whole.body);
  EXPECT_EQ(field.offset(), 0u);
  ASSERT_EQ(static_cast<size_t>(field.distances_f64_size()), grpc_field.distances.size());
  for (size_t v = 0; v < grpc_field.distances.size(); ++v) {
    EXPECT_EQ(field.distances_f64(static_cast<int>(v)), grpc_field.distances[v]) << v;
  }

  auto headers = kJson;
  headers["Accept"] = "application/x-ndjson";
  HttpReply lines = Http(port_, "POST", "/v1/meshes/hills:computeDistanceField", body, headers);
  ASSERT_EQ(lines.status, 200);
  EXPECT_EQ(lines.headers["content-type"], "application/x-ndjson");
  std::vector<std::string> messages = absl::StrSplit(lines.body, '\n', absl::SkipEmpty());
  EXPECT_EQ(messages.size(), static_cast<size_t>(grpc_field.messages));
  size_t values = 0;
  for (const std::string& line : messages) {
    const auto chunk = FromJson<v1::ComputeDistanceFieldResponse>(line);
    EXPECT_EQ(chunk.offset(), values);
    for (int k = 0; k < chunk.distances_f64_size(); ++k) {
      EXPECT_EQ(chunk.distances_f64(k), grpc_field.distances[values + k]);
    }
    values += chunk.distances_f64_size();
  }
  EXPECT_EQ(values, grpc_field.distances.size());

  // ExportGis: the file itself, with its media type.
  HttpReply geojson = Http(
      port_, "POST", "/v1/meshes/hills:exportGis",
      R"({"product": "GIS_PRODUCT_ISOCHRONES", "sources": [{"vertex": 17}], "count": 4})", kJson);
  ASSERT_EQ(geojson.status, 200) << geojson.body.substr(0, 300);
  EXPECT_EQ(geojson.headers["content-type"], "application/geo+json");
  EXPECT_TRUE(Contains(geojson.body, "\"FeatureCollection\""));
  EXPECT_GT(geojson.body.size(), 1024u);  // more than one message's worth

  // Accept: application/geo+json turns a geometry method's answer into ExportGis's GeoJSON.
  headers = kJson;
  headers["Accept"] = "application/geo+json";
  HttpReply isochrones =
      Http(port_, "POST", "/v1/meshes/hills:computeIsolines",
           R"({"sources": [{"vertex": 17}], "levels": [50, 100, 150]})", headers);
  ASSERT_EQ(isochrones.status, 200) << isochrones.body.substr(0, 300);
  EXPECT_EQ(isochrones.headers["content-type"], "application/geo+json");
  // (Read as text: google.protobuf.Struct's map code crashes under ThreadSanitizer with Debian's
  // uninstrumented libprotobuf.)
  EXPECT_TRUE(Contains(isochrones.body, "\"FeatureCollection\""));
  size_t features = 0;
  for (size_t at = 0; (at = isochrones.body.find("\"Feature\"", at)) != std::string::npos; ++at) {
    ++features;
  }
  EXPECT_EQ(features, 3u);  // one per level
  const std::string path_body = R"({"from": {"vertex": 17}, "to": {"vertex": 1000}})";
  HttpReply line = Http(port_, "POST", "/v1/meshes/hills:findShortestPath", path_body, headers);
  ASSERT_EQ(line.status, 200) << line.body.substr(0, 300);
  EXPECT_TRUE(Contains(line.body, "\"LineString\"")) << line.body.substr(0, 300);
  const size_t key = line.body.find("\"length_m\":");
  ASSERT_NE(key, std::string::npos) << line.body.substr(0, 300);
  const double length_m = std::strtod(line.body.c_str() + key + 11, nullptr);
  HttpReply plain = Http(port_, "POST", "/v1/meshes/hills:findShortestPath", path_body, kJson);
  EXPECT_NEAR(length_m, FromJson<v1::FindShortestPathResponse>(plain.body).distance(), 1e-9);
}

TEST_F(HttpEdgeTest, LimitsAndDeadlinesApplyAsOverGrpc) {
  ServerOptions options;
  options.http.max_response_bytes = 2048;
  options.limits.max_upload_bytes = 1000;
  options.result_cache_bytes = 0;
  options.samples = true;
  StartHttp(options);
  // An upload over --max_upload_bytes: refused, naming the flag (total_bytes from Content-Length).
  HttpReply upload =
      Http(port_, "POST", "/v1/meshes?display_name=hills", dem_, {{"Content-Type", "image/tiff"}});
  EXPECT_EQ(upload.status, 429) << upload.body;
  EXPECT_TRUE(Contains(upload.body, "max_upload_bytes")) << upload.body;

  HttpReply big = Http(port_, "POST", "/v1/meshes/sphere:computeDistanceField",
                       R"({"sources": [{"vertex": 0}]})", kJson);
  EXPECT_EQ(big.status, 429) << big.body.substr(0, 200);
  EXPECT_TRUE(Contains(big.body, "http_max_response_bytes")) << big.body;
  auto headers = kJson;
  headers["Accept"] = "application/x-ndjson";  // not bounded: the suggested way
  EXPECT_EQ(Http(port_, "POST", "/v1/meshes/sphere:computeDistanceField",
                 R"({"sources": [{"vertex": 0}]})", headers)
                .status,
            200);

  headers = kJson;
  // A Tobler field on the terrain sample takes about 2 s: a 100 ms deadline ends it.
  headers["grpc-timeout"] = "100m";
  HttpReply late = Http(
      port_, "POST", "/v1/meshes/terrain:computeDistanceField",
      R"({"sources": [{"vertex": 0}], "options": {"travel": {"speedModel": "SPEED_MODEL_TOBLER", "epsilon": 0.02}}})",
      headers);
  EXPECT_EQ(late.status, 504) << late.body.substr(0, 200);
  EXPECT_EQ(FromJson<google::rpc::Status>(late.body).code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes?timeout=soon").status, 400);
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes?timeout=30s").status, 200);
  headers["grpc-timeout"] = "30x";
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes", "", headers).status, 400);

  // A JSON body over --max_receive_message_bytes.
  const std::string huge(5 << 20, ' ');
  EXPECT_EQ(Http(port_, "POST", "/v1/meshes/sphere:locatePoints", huge, kJson).status, 413);
}

TEST_F(HttpEdgeTest, HostIsCheckedWithoutTokensAndCorsIsOffUnlessConfigured) {
  StartHttp();
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes", "", {{"Host", "localhost"}}).status, 200);
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes", "", {{"Host", "[::1]:80"}}).status, 200);
  HttpReply rebound = Http(port_, "GET", "/v1/meshes", "", {{"Host", "attacker.example:80"}});
  EXPECT_EQ(rebound.status, 403);
  EXPECT_TRUE(Contains(rebound.body, "http_allowed_hosts"));
  HttpReply cross = Http(port_, "GET", "/v1/meshes", "", {{"Origin", "https://app.example"}});
  EXPECT_EQ(cross.status, 200);
  EXPECT_EQ(cross.headers.count("access-control-allow-origin"), 0u);
  EXPECT_EQ(Http(port_, "OPTIONS", "/v1/meshes", "", {{"Origin", "https://app.example"}}).status,
            403);
  server_->Shutdown(absl::Now() + absl::Seconds(10));
  server_.reset();

  ServerOptions options;
  options.http.allowed_hosts = {"geodex.internal"};
  options.http.cors_origin = "https://app.example";
  StartHttp(options);
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes", "", {{"Host", "geodex.internal:8080"}}).status, 200);
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes", "", {{"Host", "other.internal"}}).status, 403);
  HttpReply allowed = Http(port_, "GET", "/v1/meshes", "", {{"Origin", "https://app.example"}});
  EXPECT_EQ(allowed.headers["access-control-allow-origin"], "https://app.example");
  HttpReply preflight = Http(port_, "OPTIONS", "/v1/meshes/sphere:findShortestPath", "",
                             {{"Origin", "https://app.example"}});
  EXPECT_EQ(preflight.status, 204);
  EXPECT_TRUE(Contains(preflight.headers["access-control-allow-headers"], "Content-Type"));
  HttpReply other = Http(port_, "GET", "/v1/meshes", "", {{"Origin", "https://evil.example"}});
  EXPECT_EQ(other.headers.count("access-control-allow-origin"), 0u);
}

TEST_F(HttpEdgeTest, TokensAreCheckedAsOverGrpc) {
  const std::string tokens = (dir_ / "tokens").string();
  std::ofstream(tokens) << "s3cret\n";
  ServerOptions options;
  options.auth_token_file = tokens;
  options.allow_plaintext_tokens = true;
  StartHttp(options);
  HttpReply anonymous = Http(port_, "GET", "/v1/meshes");
  EXPECT_EQ(anonymous.status, 401);
  EXPECT_EQ(FromJson<google::rpc::Status>(anonymous.body).code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes", "", {{"Authorization", "Bearer wrong"}}).status, 401);
  // With tokens on, a proxy's Host is fine: the token is what is checked.
  EXPECT_EQ(Http(port_, "GET", "/v1/meshes", "",
                 {{"Authorization", "Bearer s3cret"}, {"Host", "geodex.example"}})
                .status,
            200);
}

// The HTTP port is plaintext (http_edge.h): next to a TLS gRPC port it needs a TLS-terminating
// proxy, said with --allow_plaintext_tokens; otherwise geodexd refuses to start, naming the flags.
TEST(HttpEdgeOptionsTest, PlaintextHttpNextToTlsNeedsAProxy) {
  ServerOptions options;
  options.http.listen = "127.0.0.1:0";
  options.tls_cert_file = "cert.pem";
  options.tls_key_file = "key.pem";
  const absl::Status refused = ValidateServerOptions(options);
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Contains(std::string(refused.message()), "--http_listen")) << refused;
  EXPECT_TRUE(Contains(std::string(refused.message()), "--allow_plaintext_tokens")) << refused;
  options.allow_plaintext_tokens = true;
  EXPECT_TRUE(ValidateServerOptions(options).ok());
  options.http.threads = 0;
  EXPECT_TRUE(Contains(std::string(ValidateServerOptions(options).message()), "--http_threads"));
}

TEST(HttpTranscodeTest, RoutesFollowTheServiceDescriptor) {
  HttpRequest request;
  request.method = "POST";
  request.content_type = "application/json; charset=utf-8";
  for (const char* verb :
       {"findShortestPath", "findShortestPaths", "computeDistanceField", "computeDistanceMatrix",
        "estimateDistances", "locatePoints", "computeIsolines", "computeVoronoi", "computeDelaunay",
        "exportGis", "deriveMesh", "getMeshGeometry"}) {
    request.path = absl::StrCat("/v1/meshes/m1:", verb);
    absl::StatusOr<HttpCall> call = RouteHttpRequest(request);
    ASSERT_TRUE(call.ok()) << verb << ": " << call.status();
    std::string method = verb;
    method[0] = static_cast<char>(absl::ascii_toupper(method[0]));
    EXPECT_EQ(call->grpc_method, absl::StrCat("/geodex.v1.Geodex/", method));
    EXPECT_EQ(call->answer, method == "ExportGis" ? HttpAnswer::kFile : HttpAnswer::kJson);
  }
  request.path = "/v1/meshes/m1:createMesh";  // the upload is POST /v1/meshes
  EXPECT_EQ(RouteHttpRequest(request).status().code(), absl::StatusCode::kNotFound);
  request.path = "/v1/meshes/a/b:findShortestPath";
  EXPECT_EQ(RouteHttpRequest(request).status().code(), absl::StatusCode::kNotFound);

  EXPECT_EQ(*ParseTimeoutSeconds("30S", true, "h"), 30);
  EXPECT_EQ(*ParseTimeoutSeconds("500m", true, "h"), 0.5);
  EXPECT_EQ(*ParseTimeoutSeconds("2M", true, "h"), 120);
  EXPECT_EQ(*ParseTimeoutSeconds("500ms", false, "q"), 0.5);
  EXPECT_EQ(*ParseTimeoutSeconds("2m", false, "q"), 120);
  for (const char* bad : {"", "S", "-1S", "1.5S", "0S", "999999999S"}) {
    EXPECT_FALSE(ParseTimeoutSeconds(bad, true, "h").ok()) << bad;
  }
  EXPECT_FALSE(ParseTimeoutSeconds("-1s", false, "q").ok());
  EXPECT_FALSE(ParseTimeoutSeconds("inf", false, "q").ok());

  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::INVALID_ARGUMENT), 400);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::UNAUTHENTICATED), 401);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::PERMISSION_DENIED), 403);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::NOT_FOUND), 404);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::ALREADY_EXISTS), 409);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::RESOURCE_EXHAUSTED), 429);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::UNAVAILABLE), 503);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::DEADLINE_EXCEEDED), 504);
  EXPECT_EQ(HttpStatusOf(grpc::StatusCode::DATA_LOSS), 500);
}

}  // namespace
}  // namespace geodex::server
