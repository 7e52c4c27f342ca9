#pragma once

// The one place where absl::Status (core and server code) becomes grpc::Status. Besides code and
// message, errors carry google.rpc.Status details (grpc-status-details-bin): INVALID_ARGUMENT a
// google.rpc.BadRequest naming the field ("sources[1].vertex"), RESOURCE_EXHAUSTED a
// google.rpc.ErrorInfo (domain "geodex.v1"; reason LIMIT with metadata flag=<server flag>,
// QUEUE_FULL, or RESOURCE_EXHAUSTED for the mesh budget).

#include "absl/status/status.h"
#include "grpcpp/support/status.h"

namespace geodex::server {

grpc::Status ToGrpcStatus(const absl::Status& status);

}  // namespace geodex::server
