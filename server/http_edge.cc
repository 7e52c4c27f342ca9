#include "http_edge.h"

#include <algorithm>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "civetweb.h"
#include "grpcpp/client_context.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/support/byte_buffer.h"
#include "http_transcode.h"
#include "listen_address.h"
#include "map_assets.h"
#include "spdlog/spdlog.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

// One gRPC call over the in-process channel, driven step by step on its own completion queue (the
// HTTP thread waits; the call runs on the server's reactors and compute pool).
class GenericCall {
 public:
  GenericCall(grpc::Channel* channel, grpc::ClientContext* context, const std::string& method)
      : stub_(std::shared_ptr<grpc::Channel>(channel, [](grpc::Channel*) {})) {
    call_ = stub_.PrepareCall(context, method, &queue_);
    call_->StartCall(Tag(1));
    ok_ = Wait();
  }
  ~GenericCall() {
    queue_.Shutdown();
    void* tag;
    bool ok;
    while (queue_.Next(&tag, &ok)) {
    }
  }
  // False once the server has ended the call (Finish then says why).
  bool Write(const std::string& bytes) {
    if (!ok_) return false;
    grpc::Slice slice(bytes);
    grpc::ByteBuffer buffer(&slice, 1);
    call_->Write(buffer, Tag(2));
    return ok_ = Wait();
  }
  void WritesDone() {
    if (!ok_) return;
    call_->WritesDone(Tag(3));
    ok_ = Wait();
  }
  bool Read(std::string* bytes) {
    grpc::ByteBuffer buffer;
    call_->Read(&buffer, Tag(4));
    if (!Wait()) return false;
    std::vector<grpc::Slice> slices;
    if (!buffer.Dump(&slices).ok()) return false;
    bytes->clear();
    for (const grpc::Slice& s : slices)
      bytes->append(reinterpret_cast<const char*>(s.begin()), s.size());
    return true;
  }
  grpc::Status Finish() {
    grpc::Status status;
    call_->Finish(&status, Tag(5));
    Wait();
    return status;
  }

 private:
  static void* Tag(intptr_t n) { return reinterpret_cast<void*>(n); }
  bool Wait() {
    void* tag;
    bool ok = false;
    return queue_.Next(&tag, &ok) && ok;
  }
  grpc::GenericStub stub_;
  grpc::CompletionQueue queue_;
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call_;
  bool ok_ = false;
};

std::string Header(mg_connection* connection, const char* name) {
  const char* value = mg_get_header(connection, name);
  return value == nullptr ? "" : value;
}

// The host part of a Host header ("localhost:8080" -> "localhost", "[::1]:80" -> "[::1]").
std::string HostName(const std::string& host) {
  if (!host.empty() && host[0] == '[') return host.substr(0, host.find(']') + 1);
  return absl::AsciiStrToLower(host.substr(0, host.find(':')));
}

struct Answer {
  int status = 200;
  std::string media_type = "application/json";
  std::string body;
};

}  // namespace

absl::Status ValidateHttpEdgeOptions(const HttpEdgeOptions& options) {
  if (options.listen.empty()) return absl::OkStatus();
  if (absl::Status s = ValidateListenAddress(options.listen, "http_listen"); !s.ok()) return s;
  if (absl::StartsWith(options.listen, "unix") || absl::StartsWith(options.listen, "[")) {
    return absl::InvalidArgumentError(
        absl::StrCat("--http_listen=", options.listen, ": the HTTP port takes an IPv4 HOST:PORT"));
  }
  if (options.threads < 1 || options.threads > kMaxHttpThreads) {
    return absl::InvalidArgumentError(
        absl::StrCat("--http_threads=", options.threads, ": from 1 to ", kMaxHttpThreads));
  }
  if (!options.grpc_target.empty()) {
    if (absl::Status s = ValidateListenAddress(options.grpc_target, "http_grpc_target"); !s.ok()) {
      return s;
    }
  }
  if (options.max_response_bytes < 1024) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--http_max_response_bytes=", options.max_response_bytes, ": must be at least 1024"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<HttpEdge>> HttpEdge::Start(const HttpEdgeOptions& options,
                                                          std::shared_ptr<grpc::Channel> channel) {
  if (absl::Status valid = ValidateHttpEdgeOptions(options); !valid.ok()) return valid;
  std::unique_ptr<HttpEdge> edge(new HttpEdge());
  edge->options_ = options;
  edge->channel_ = std::move(channel);
  mg_init_library(0);

  std::string host = options.listen.substr(0, options.listen.rfind(':'));
  const std::string port = options.listen.substr(options.listen.rfind(':') + 1);
  if (host == "localhost") host = "127.0.0.1";
  const std::string ports = absl::StrCat(host.empty() ? "" : host + ":", port);
  const std::string threads = absl::StrCat(options.threads);
  // No document_root: nothing but the handler below answers, and no file is ever served.
  const char* settings[] = {"listening_ports",
                            ports.c_str(),
                            "num_threads",
                            threads.c_str(),
                            "request_timeout_ms",
                            "30000",
                            "enable_keep_alive",
                            "yes",
                            "keep_alive_timeout_ms",
                            "5000",
                            "tcp_nodelay",  // chunks (NDJSON) leave as they are written
                            "1",
                            nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = [](const mg_connection*, const char* message) {
    spdlog::warn("http: {}", message);
    return 1;
  };
  edge->context_ = mg_start(&callbacks, edge.get(), settings);
  if (edge->context_ == nullptr) {
    mg_exit_library();
    if (AddressInUse(options.listen)) {
      return absl::UnavailableError(
          absl::StrCat("--http_listen=", options.listen, ": address in use; choose another port"));
    }
    return absl::UnavailableError(
        absl::StrCat("--http_listen=", options.listen, ": cannot listen"));
  }
  mg_set_request_handler(edge->context_, "/", &HttpEdge::Handle, edge.get());
  mg_server_port bound[4];
  const int n = mg_get_server_ports(edge->context_, 4, bound);
  edge->port_ = n > 0 ? bound[0].port : 0;
  return edge;
}

HttpEdge::~HttpEdge() { Stop(); }

void HttpEdge::Stop() {
  if (context_ == nullptr) return;
  mg_stop(context_);
  context_ = nullptr;
  mg_exit_library();
}

int HttpEdge::Handle(mg_connection* connection, void* self) {
  return static_cast<HttpEdge*>(self)->Serve(connection);
}

int HttpEdge::Serve(mg_connection* connection) {
  const mg_request_info* info = mg_get_request_info(connection);
  const std::string origin = Header(connection, "Origin");
  const bool cors = !options_.cors_origin.empty() && !origin.empty() &&
                    (options_.cors_origin == "*" || origin == options_.cors_origin);
  std::string replica;  // the x-geodex-replica the call answered with: which replica served it
  std::string extra_headers;
  // The head of an answer; `body` goes out in the same write (headers and body in two small writes
  // wait for the client's delayed ACK under Nagle's algorithm: 40 ms a call).
  auto send_head = [&](int status, const std::string& media_type, int64_t length,
                       const std::string& body = "") {
    std::string head =
        absl::StrCat("HTTP/1.1 ", status, " ", mg_get_response_code_text(connection, status),
                     "\r\nContent-Type: ", media_type,
                     "\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n");
    if (!replica.empty()) absl::StrAppend(&head, "X-Geodex-Replica: ", replica, "\r\n");
    head += extra_headers;
    if (cors)
      absl::StrAppend(&head, "Access-Control-Allow-Origin: ", origin, "\r\nVary: Origin\r\n");
    absl::StrAppend(&head,
                    length >= 0 ? absl::StrCat("Content-Length: ", length, "\r\n")
                                : std::string("Transfer-Encoding: chunked\r\n"),
                    "\r\n");
    head += body;
    mg_write(connection, head.data(), head.size());
  };
  auto send = [&](const Answer& answer) {
    const bool head_only = std::string(info->request_method) == "HEAD";
    send_head(answer.status, answer.media_type, static_cast<int64_t>(answer.body.size()),
              head_only ? std::string() : answer.body);
    return answer.status;
  };
  auto refuse = [&](const grpc::Status& status, int http_status = 0) {
    return send({http_status != 0 ? http_status : HttpStatusOf(status.error_code()),
                 "application/json", ErrorJson(status)});
  };

  // DNS rebinding: without tokens, only a Host that names this machine (or an allowed one).
  if (!options_.tokens) {
    const std::string host = HostName(Header(connection, "Host"));
    const bool local = host == "localhost" || host == "127.0.0.1" || host == "[::1]";
    const bool allowed = std::any_of(
        options_.allowed_hosts.begin(), options_.allowed_hosts.end(),
        [&](const std::string& a) { return a == "*" || absl::AsciiStrToLower(a) == host; });
    if (!local && !allowed) {
      return refuse(
          grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                       absl::StrCat("Host ", host.empty() ? "(none)" : host,
                                    ": not this server's; add it to --http_allowed_hosts")));
    }
  }
  const std::string method = info->request_method;
  if (method == "OPTIONS") {  // a CORS preflight
    if (!cors) {
      return refuse(grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                                 "cross-origin requests are off (--http_cors_origin)"),
                    403);
    }
    const std::string head =
        absl::StrCat("HTTP/1.1 204 No Content\r\nAccess-Control-Allow-Origin: ", origin,
                     "\r\nVary: Origin\r\nAccess-Control-Allow-Methods: GET, POST, DELETE"
                     "\r\nAccess-Control-Allow-Headers: Content-Type, Authorization, grpc-timeout"
                     "\r\nAccess-Control-Max-Age: 600\r\nContent-Length: 0\r\n\r\n");
    mg_write(connection, head.data(), head.size());
    return 204;
  }

  // The map page and its files (map_assets.h): only what is built in, never a file from disk.
  const std::string path = info->local_uri != nullptr ? info->local_uri : "";
  if ((method == "GET" || method == "HEAD") && !absl::StartsWith(path, "/v1/")) {
    for (const MapAsset& asset : MapAssets()) {
      if (path != asset.path) continue;
      // The page loads only its own files; Leaflet sets inline styles; the hillshade is a data URL.
      extra_headers =
          "Content-Security-Policy: default-src 'self'; img-src 'self' data: blob:; "
          "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'\r\n";
      return send({200, MapAssetMediaType(path), std::string(asset.bytes)});
    }
  }

  HttpRequest request;
  request.method = method;
  request.path = path;
  request.query = info->query_string != nullptr ? info->query_string : "";
  request.content_type = Header(connection, "Content-Type");
  request.accept = Header(connection, "Accept");
  request.content_length = info->content_length;
  if (method == "POST" && !IsUploadRequest(method, path)) {  // the JSON body, bounded
    if (info->content_length > static_cast<int64_t>(options_.max_body_bytes)) {
      return refuse(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                                 absl::StrCat("body of ", info->content_length,
                                              " bytes: over --max_receive_message_bytes=",
                                              options_.max_body_bytes)),
                    413);
    }
    char buffer[16384];
    int got;
    while ((got = mg_read(connection, buffer, sizeof(buffer))) > 0) {
      request.body.append(buffer, got);
      if (request.body.size() > options_.max_body_bytes) {
        return refuse(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                                   absl::StrCat("body over --max_receive_message_bytes=",
                                                options_.max_body_bytes)),
                      413);
      }
    }
  }
  absl::StatusOr<HttpCall> routed = RouteHttpRequest(request);
  if (!routed.ok()) {
    const absl::StatusCode code = routed.status().code();
    return refuse(ToGrpcStatus(routed.status()), code == absl::StatusCode::kUnimplemented ? 405
                                                 : code == absl::StatusCode::kFailedPrecondition
                                                     ? 415
                                                     : 0);
  }
  const HttpCall& call = *routed;

  grpc::ClientContext context;
  double timeout = call.timeout_seconds;
  if (const std::string header = Header(connection, "grpc-timeout"); !header.empty()) {
    absl::StatusOr<double> seconds = ParseTimeoutSeconds(header, true, "header grpc-timeout");
    if (!seconds.ok()) return refuse(ToGrpcStatus(seconds.status()));
    timeout = timeout > 0 ? std::min(timeout, *seconds) : *seconds;
  }
  if (timeout > 0) {
    context.set_deadline(std::chrono::system_clock::now() +
                         std::chrono::microseconds(static_cast<int64_t>(timeout * 1e6)));
  }
  if (const std::string auth = Header(connection, "Authorization"); !auth.empty()) {
    context.AddMetadata("authorization", auth);
  }
  if (!call.mesh_key.empty()) context.AddMetadata("x-mesh-id", call.mesh_key);

  GenericCall rpc(channel_.get(), &context, call.grpc_method);
  bool writing = rpc.Write(call.request);
  if (call.upload) {  // the body in 1 MiB chunks, as it arrives
    std::string chunk(1 << 20, '\0');
    int got;
    while (writing && (got = mg_read(connection, chunk.data(), chunk.size())) > 0) {
      writing = rpc.Write(UploadChunkMessage(call, chunk.substr(0, got)));
    }
  }
  rpc.WritesDone();
  auto note_replica = [&] {  // valid once the call's initial metadata arrived
    const auto& metadata = context.GetServerInitialMetadata();
    const auto found = metadata.find("x-geodex-replica");
    if (found == metadata.end()) return;
    replica.assign(found->second.data(), found->second.size());
    replica.erase(std::remove_if(replica.begin(), replica.end(),
                                 [](char c) { return c == '\r' || c == '\n'; }),
                  replica.end());
  };

  HttpAnswerBuilder answer(call, options_.max_response_bytes);
  bool streaming = false;  // headers sent: the answer goes out in chunks
  std::string message, out;
  absl::Status assembled;
  while (rpc.Read(&message)) {
    if (replica.empty()) note_replica();
    if (!assembled.ok()) continue;  // drain what the cancelled call still sends
    assembled = answer.Add(message, &out);
    if (!assembled.ok()) {
      context.TryCancel();
      continue;
    }
    if (call.answer == HttpAnswer::kNdjson) {
      if (!streaming) send_head(200, answer.media_type(), -1);
      streaming = true;
      if (!out.empty() && mg_send_chunk(connection, out.data(), out.size()) < 0) {
        context.TryCancel();  // the client went away: the solve stops
      }
    }
  }
  const grpc::Status status = rpc.Finish();
  if (replica.empty()) note_replica();
  if (streaming) {  // NDJSON: an error is the stream's last line
    if (!status.ok() || !assembled.ok()) {
      const std::string line = absl::StrCat(
          "{\"error\": ", ErrorJson(status.ok() ? ToGrpcStatus(assembled) : status), "}\n");
      mg_send_chunk(connection, line.data(), line.size());
    }
    mg_send_chunk(connection, "", 0);
    return status.ok() ? 200 : HttpStatusOf(status.error_code());
  }
  if (!assembled.ok()) return refuse(ToGrpcStatus(assembled));
  if (!status.ok()) return refuse(status);
  return send({200, answer.media_type(), answer.Finish()});
}

}  // namespace geodex::server
