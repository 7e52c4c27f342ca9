#pragma once

// The one place where absl::Status (core and server code) becomes grpc::Status, and where the
// server's typed errors are made. Besides code and message, errors carry google.rpc.Status details
// (grpc-status-details-bin), from the status's payloads only:
//   INVALID_ARGUMENT    google.rpc.BadRequest naming the field ("sources[1].vertex", FieldError);
//   RESOURCE_EXHAUSTED  google.rpc.ErrorInfo (domain "geodex.v1"; reason LIMIT with metadata
//                       flag=<server flag> (ServerLimitError, core limits), QUEUE_FULL, or
//                       RESOURCE_EXHAUSTED for the mesh budget);
//   NOT_FOUND           google.rpc.ErrorInfo reason MESH_NOT_FOUND (MeshNotFoundError);
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

// Typed errors. What a client acts on (the field, the flag, the reason) travels as data:
// absl::Status payloads that ToGrpcStatus turns into google.rpc details, never parsed back out of a
// message.
//
// INVALID_ARGUMENT "FIELD: DESCRIPTION", with a BadRequest naming FIELD ("sources[2].edge.t").
absl::Status FieldError(absl::string_view field, absl::string_view description);
// RESOURCE_EXHAUSTED over a server limit, with ErrorInfo reason LIMIT and metadata flag=FLAG
// ("max_targets"); the message names the flag for people.
absl::Status ServerLimitError(absl::string_view flag, absl::string_view message);
// RESOURCE_EXHAUSTED with ErrorInfo reason QUEUE_FULL: every worker busy, retry later.
absl::Status QueueFullError(absl::string_view message);
// NOT_FOUND "FIELD: mesh ... not found" with ErrorInfo reason MESH_NOT_FOUND (and a BadRequest
// naming FIELD): a client that has the mesh's file uploads it again.
absl::Status MeshNotFoundError(absl::string_view field, absl::string_view message);
// FAILED_PRECONDITION with ErrorInfo reason UNREACHABLE: the query's target is not reachable from
// its source (another component, or beyond max_distance). Not NOT_FOUND, which means an unknown
// mesh.
absl::Status UnreachableError(absl::string_view message);

}  // namespace geodex::server
