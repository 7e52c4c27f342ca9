#pragma once

// The HTTP/JSON edge's translation, without the network (http_edge.h serves it): an HTTP request
// becomes a geodex.v1 call, and the call's messages and status become an HTTP answer. Routes follow
// Google's HTTP-to-gRPC transcoding convention, read off the service's descriptor, so the proto
// stays the one source of truth (docs/service.md, "HTTP/JSON"):
//   GET    /v1/meshes                      ListMeshes (query parameters: the request's fields)
//   POST   /v1/meshes                      CreateMesh: the body is the file; the metadata's fields
//                                          (display_name, format, dem.step, ...) as query
//                                          parameters
//   GET    /v1/meshes/{id}                 GetMesh
//   DELETE /v1/meshes/{id}                 DeleteMesh
//   POST   /v1/meshes/{id}:{rpc}           any other method, lowerCamelCase (":findShortestPath");
//                                          the body is the request in protobuf's JSON mapping, its
//                                          `mesh` (or `name`) taken from the path
// Answers are the response message's JSON (lowerCamelCase names, every field printed); a streamed
// answer is assembled into one message (or sent as NDJSON, one message a line, when the request
// accepts application/x-ndjson); ExportGis answers the file itself with its media type, and so do
// isolines, Voronoi, Delaunay, a path and point distances asked with Accept: application/geo+json
// (as the ExportGis product of the same request: RFC 7946 GeoJSON). Errors are
// google.rpc.Status JSON with the HTTP code the convention maps the gRPC code to.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "google/protobuf/descriptor.h"
#include "google/protobuf/message.h"
#include "grpcpp/support/status.h"

namespace geodex::server {

// What the edge needs of an HTTP request (the body only for JSON routes: uploads stream theirs).
struct HttpRequest {
  std::string method;           // "GET", "POST", ...
  std::string path;             // URL-decoded path, without the query
  std::string query;            // raw query string (percent-encoded), without '?'
  std::string content_type;     // the Content-Type header ("" when absent)
  std::string accept;           // the Accept header
  std::string body;             // the JSON body (not for uploads)
  int64_t content_length = -1;  // an upload's size when the request states it
};

// How an answer is written.
enum class HttpAnswer {
  kJson,    // one JSON object (a stream assembled into one message)
  kNdjson,  // one JSON object per streamed message, a line each
  kFile,    // ExportGis: the file's bytes (whole) with its media type
};

// A routed call: the method and its request, ready to send.
struct HttpCall {
  const google::protobuf::MethodDescriptor* method = nullptr;
  std::string grpc_method;  // "/geodex.v1.Geodex/FindShortestPath"
  bool upload = false;      // CreateMesh: `request` is its metadata; the body follows in chunks
  std::string request;      // the serialized request (for an upload, its first message)
  HttpAnswer answer = HttpAnswer::kJson;
  double timeout_seconds = 0;  // from ?timeout= (0: none asked)
  // The mesh the call is about, as gRPC clients send it in x-mesh-id for a gateway: the path's
  // mesh, or an upload's expected_mesh_id ("" when neither).
  std::string mesh_key;
};

// The route of a request: NotFound for no route (naming the path), InvalidArgument for a body or
// query parameter that does not parse (naming it), Unimplemented for a known path asked with the
// wrong HTTP method (the edge answers 405), FailedPrecondition for a media type a route does not
// take (415). The path's mesh becomes the request's `mesh` (or `name`): "meshes/{id}".
absl::StatusOr<HttpCall> RouteHttpRequest(const HttpRequest& request);

// Whether the request is an upload (POST of the collection): its body is the file, streamed into
// CreateMesh, not a JSON body read whole before routing.
bool IsUploadRequest(const std::string& method, const std::string& path);

// Whether a Content-Type is one an upload's body may have: anything but the types a browser form
// can post without a CORS preflight (text/plain, forms), so no web page can upload behind a user's
// back.
bool IsUploadMediaType(const std::string& content_type);

// Builds an answer from the call's streamed messages (each serialized); adds one at a time.
class HttpAnswerBuilder {
 public:
  // `max_bytes` bounds an assembled answer (--http_max_response_bytes).
  HttpAnswerBuilder(const HttpCall& call, uint64_t max_bytes);
  // Adds the next message. For kNdjson `*out` receives the line to send now; kJson and kFile are
  // sent whole by Finish. ResourceExhausted (naming --http_max_response_bytes) when an
  // assembled answer grows past the limit; InvalidArgument for a message that does not parse.
  absl::Status Add(const std::string& message, std::string* out);
  // The rest of the answer: the assembled JSON (kJson) or file (kFile); nothing for kNdjson.
  std::string Finish();
  // The media type to announce (known for kFile after the first message).
  std::string media_type() const;

 private:
  const HttpCall& call_;
  uint64_t max_bytes_;
  uint64_t bytes_ = 0;
  size_t messages_ = 0;
  std::unique_ptr<google::protobuf::Message> assembled_;
  uint64_t first_offset_ = 0;
  std::string file_media_type_;
  std::string file_;
};

// The JSON of a message as the edge writes it (lowerCamelCase, every field printed).
std::string MessageToHttpJson(const google::protobuf::Message& message);

// An error answer: the HTTP status of a gRPC code (Google's transcoding table: INVALID_ARGUMENT
// 400, UNAUTHENTICATED 401, NOT_FOUND 404, RESOURCE_EXHAUSTED 429, UNAVAILABLE 503,
// DEADLINE_EXCEEDED 504, ...), and the google.rpc.Status JSON with the details the gRPC answer
// carries.
int HttpStatusOf(grpc::StatusCode code);
std::string ErrorJson(const grpc::Status& status);

// A duration in gRPC's grpc-timeout form ("30S", "500m", "2M": the header) or absl's ("30s",
// "1.5s", "2m": the query parameter); InvalidArgument naming `what` otherwise, or for zero.
absl::StatusOr<double> ParseTimeoutSeconds(const std::string& text, bool grpc_form,
                                           const std::string& what);

// The CreateMesh message carrying the next `bytes` of an upload's body.
std::string UploadChunkMessage(const HttpCall& call, const std::string& bytes);

}  // namespace geodex::server
