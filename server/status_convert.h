#pragma once

// The one place where absl::Status (core and server code) becomes grpc::Status.

#include "absl/status/status.h"
#include "grpcpp/support/status.h"

namespace geodex::server {

grpc::Status ToGrpcStatus(const absl::Status& status);

}  // namespace geodex::server
