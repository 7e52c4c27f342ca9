// TLS and bearer tokens: a self-signed certificate made at test time (openssl), geodex.v1 calls
// need a valid token, health stays open, a plaintext client cannot talk to a TLS server, and no
// combination of credentials brings the server down.

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "geodex/geodex_client.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

using client::ClientOptions;
using client::GeodexClient;
using testing::GridOff;

namespace fs = std::filesystem;

class SecurityTest : public testing::ServerFixture {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           absl::StrCat("geodex-security-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const std::string command = absl::StrCat(
        "openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=localhost ",
        "-addext subjectAltName=IP:127.0.0.1,DNS:localhost -keyout ", (dir_ / "key.pem").string(),
        " -out ", (dir_ / "cert.pem").string(), " >/dev/null 2>&1");
    ASSERT_EQ(std::system(command.c_str()), 0) << "openssl could not make a certificate";
    std::ofstream(dir_ / "tokens") << "# tokens\n  s3cret-one  \n\nsecond-token\n";
  }
  void TearDown() override {
    testing::ServerFixture::TearDown();
    fs::remove_all(dir_);
  }
  std::string Read(const char* name) {
    std::ifstream in(dir_ / name);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  void StartSecure(bool tls, bool tokens) {
    ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.pool_threads = 2;
    if (tls) {
      options.tls_cert_file = (dir_ / "cert.pem").string();
      options.tls_key_file = (dir_ / "key.pem").string();
    }
    if (tokens) options.auth_token_file = (dir_ / "tokens").string();
    if (tokens && !tls) {
      // Tokens in plaintext are refused unless a TLS-terminating proxy is declared.
      auto refused = GeodexServer::Start(options);
      ASSERT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
      EXPECT_NE(refused.status().message().find("--allow_plaintext_tokens"), std::string::npos)
          << refused.status();
      options.allow_plaintext_tokens = true;
    }
    auto server = GeodexServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
    EXPECT_EQ(server_->tls(), tls);
    EXPECT_EQ(server_->authenticated(), tokens);
  }
  GeodexClient Client(bool tls, const std::string& token) {
    ClientOptions options;
    options.target = absl::StrCat("127.0.0.1:", server_->port());
    options.tls = tls;
    if (tls) options.ca_pem = Read("cert.pem");
    options.token = token;
    options.deadline_seconds = 30;
    options.max_attempts = 1;
    return GeodexClient(options);
  }
  // Upload + field through the client: the status of the first failing step.
  absl::Status Use(GeodexClient& client) {
    const std::string path = (dir_ / "grid.off").string();
    std::ofstream(path) << GridOff(5, 5, true);
    absl::StatusOr<client::MeshRef> mesh = client.ResolveMesh(path);
    if (!mesh.ok()) return mesh.status();
    return client.Field(*mesh, FieldQuery{{SurfacePoint::AtVertex(0)}, {}, false}).status();
  }

  fs::path dir_;
};

TEST_F(SecurityTest, TlsWithTokensNeedsAValidToken) {
  StartSecure(/*tls=*/true, /*tokens=*/true);
  GeodexClient good = Client(true, "s3cret-one");
  EXPECT_TRUE(Use(good).ok()) << Use(good);
  GeodexClient second = Client(true, "second-token");
  EXPECT_TRUE(Use(second).ok());

  for (const char* token : {"", "wrong", "s3cret-on", "s3cret-one2"}) {
    GeodexClient bad = Client(true, token);
    absl::Status s = Use(bad);
    EXPECT_EQ(s.code(), absl::StatusCode::kUnauthenticated) << token << ": " << s;
    EXPECT_NE(s.message().find("bearer token"), std::string::npos);
    EXPECT_EQ(s.message().find("s3cret"), std::string::npos);  // never echoes a token
  }
  // Health stays open without a token; every streamed and unary method is guarded.
  GeodexClient anonymous = Client(true, "");
  EXPECT_TRUE(*anonymous.Health());
  EXPECT_EQ(anonymous.ListMeshes().status().code(), absl::StatusCode::kUnauthenticated);
  EXPECT_EQ(anonymous.DeleteMesh("meshes/x").code(), absl::StatusCode::kUnauthenticated);
  client::MeshRef ref{
      "meshes/" + std::string(64, 'a'), std::string(64, 'a'), "", "", false, std::nullopt};
  EXPECT_EQ(anonymous.Locate(ref, {{0, 0, 0}}).status().code(), absl::StatusCode::kUnauthenticated);
  EXPECT_EQ(
      anonymous.ComputeVoronoi(ref, VoronoiQuery{{SurfacePoint::AtVertex(0)}, {}}).status().code(),
      absl::StatusCode::kUnauthenticated);
  // The server is still serving the good client.
  EXPECT_TRUE(Use(good).ok());
}

TEST_F(SecurityTest, PlaintextClientCannotTalkToATlsServer) {
  StartSecure(/*tls=*/true, /*tokens=*/false);
  GeodexClient plaintext = Client(false, "");
  // The handshake never completes: UNAVAILABLE, never an answer (nor a hang: the call's deadline).
  const absl::StatusOr<bool> health = plaintext.Health();
  EXPECT_EQ(health.status().code(), absl::StatusCode::kUnavailable) << health.status();
  GeodexClient tls = Client(true, "");
  EXPECT_TRUE(Use(tls).ok());
}

TEST_F(SecurityTest, TokensWithoutTlsWorkAndNeverAbort) {
  // (gRPC's AuthMetadataProcessor would abort the process on insecure credentials.)
  StartSecure(/*tls=*/false, /*tokens=*/true);
  GeodexClient good = Client(false, "second-token");
  EXPECT_TRUE(Use(good).ok());
  GeodexClient bad = Client(false, "nope");
  EXPECT_EQ(Use(bad).code(), absl::StatusCode::kUnauthenticated);
  EXPECT_TRUE(*bad.Health());
}

TEST_F(SecurityTest, BadSecuritySettingsFailToStartWithAClearError) {
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.tls_cert_file = (dir_ / "cert.pem").string();  // without a key
  auto server = GeodexServer::Start(options);
  EXPECT_EQ(server.status().code(), absl::StatusCode::kInvalidArgument);
  options.tls_key_file = (dir_ / "missing.pem").string();
  server = GeodexServer::Start(options);
  EXPECT_NE(server.status().message().find("--tls_key"), std::string::npos) << server.status();
  ServerOptions tokens;
  tokens.listen = "127.0.0.1:0";
  std::ofstream(dir_ / "empty") << "# nothing\n\n";
  tokens.auth_token_file = (dir_ / "empty").string();
  tokens.allow_plaintext_tokens = true;
  server = GeodexServer::Start(tokens);
  EXPECT_NE(server.status().message().find("no token"), std::string::npos) << server.status();
}

}  // namespace
}  // namespace geodex::server
