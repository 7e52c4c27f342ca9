#pragma once

// geodexd's HTTP/JSON port (--http_listen): civetweb (Debian's libcivetweb, MIT; prometheus-cpp
// already serves /metrics with it) in front of the gRPC service. Each HTTP request is translated
// (http_transcode.h) into one geodex.v1 call over the server's in-process channel, so it passes the
// same authentication, limits, compute pool, metrics and log lines as a gRPC call: HTTP is an edge,
// never a second implementation of a query. Its own threads (--http_threads) only wait for calls;
// the compute pool's queue bounds the work (a full queue answers 429).
//
// Safe by default: without bearer tokens a request's Host must name this machine (localhost,
// 127.0.0.1, [::1]) or one of --http_allowed_hosts, so a web page cannot reach geodex through DNS
// rebinding; a POST needs a JSON (or, for uploads, a file) media type, which a cross-site form
// cannot send; CORS is off unless --http_cors_origin names an origin. The port speaks plaintext
// HTTP only: Debian's civetweb 1.15 loads OpenSSL at run time and its TLS connections were reset
// (its own `civetweb` binary too), so next to --tls_cert the port needs a TLS-terminating proxy
// in front (geodex_server.cc refuses it otherwise).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "grpcpp/channel.h"

struct mg_context;
struct mg_connection;

namespace geodex::server {

struct HttpEdgeOptions {
  std::string listen;                      // HOST:PORT (port 0: a free one); "" = no HTTP port
  size_t threads = 4;                      // --http_threads: connections served at once
  uint64_t max_body_bytes = 4 << 20;       // a JSON body (--max_receive_message_bytes)
  uint64_t max_response_bytes = 64 << 20;  // --http_max_response_bytes: an assembled answer
  std::vector<std::string> allowed_hosts;  // --http_allowed_hosts ("*": any)
  std::string cors_origin;                 // --http_cors_origin ("" = no CORS)
  bool tokens = false;                     // bearer tokens on: Host is not checked
  // --http_grpc_target: where the calls go. "" = this server, in-process; HOST:PORT = a gateway's
  // gRPC port (plaintext), so that HTTP calls are routed by mesh exactly as gRPC calls are (each
  // carries its mesh as x-mesh-id; deploy/gateway).
  std::string grpc_target;
};
inline constexpr size_t kMaxHttpThreads = 256;

// InvalidArgument naming the flag for settings that cannot work.
absl::Status ValidateHttpEdgeOptions(const HttpEdgeOptions& options);

class HttpEdge {
 public:
  // Starts serving; Unavailable naming --http_listen when it cannot listen.
  static absl::StatusOr<std::unique_ptr<HttpEdge>> Start(const HttpEdgeOptions& options,
                                                         std::shared_ptr<grpc::Channel> channel);
  ~HttpEdge();  // Stop()

  int port() const { return port_; }
  // Stops accepting and waits for the requests being served (their calls end with the server's).
  void Stop();

 private:
  HttpEdge() = default;
  static int Handle(mg_connection* connection, void* self);
  int Serve(mg_connection* connection);

  HttpEdgeOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  mg_context* context_ = nullptr;
  int port_ = 0;
};

}  // namespace geodex::server
