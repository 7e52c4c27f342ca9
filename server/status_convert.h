#pragma once

// The one place where absl::Status (core and server code) becomes grpc::Status. Besides code and
// message, errors carry google.rpc.Status details (grpc-status-details-bin):
//   INVALID_ARGUMENT    google.rpc.BadRequest naming the field ("sources[1].vertex");
//   RESOURCE_EXHAUSTED  google.rpc.ErrorInfo (domain "geodex.v1"; reason LIMIT with metadata
//                       flag=<server flag>, QUEUE_FULL, or RESOURCE_EXHAUSTED for the mesh budget);
//   FAILED_PRECONDITION google.rpc.ErrorInfo reason UNREACHABLE (UnreachableError).
// A core limit error (geodex/limits.h) gets the name of the server flag that set the limit. Every
// message is capped at kMaxStatusMessageBytes, so that a client's default 8 KiB metadata limit
// always lets the real status through.

#include <cstddef>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "grpcpp/support/status.h"

namespace geodex::server {

inline constexpr size_t kMaxEchoBytes = 200;
inline constexpr size_t kMaxStatusMessageBytes = 2000;

grpc::Status ToGrpcStatus(const absl::Status& status);

// Client input quoted for an error message: at most kMaxEchoBytes of it, marked when cut
// ("\"abc...\" (cut: 1048576 bytes)").
std::string QuoteInput(absl::string_view input);

// FAILED_PRECONDITION with ErrorInfo reason UNREACHABLE: the query's target is not reachable from
// its source (another component, or beyond max_distance). Not NOT_FOUND, which means an unknown
// mesh.
absl::Status UnreachableError(absl::string_view message);

}  // namespace geodex::server
