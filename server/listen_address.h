#pragma once

// Checks of the addresses geodexd listens on (--listen, --metrics_listen).

#include <string>

#include "absl/status/status.h"

namespace geodex::server {

// HOST:PORT with an explicit port (0 = any free port); an IPv6 host in brackets ("[::1]:50051");
// or a "unix:" socket path. InvalidArgument naming `flag` otherwise: gRPC would read "127.0.0.1"
// as port 443.
absl::Status ValidateListenAddress(const std::string& address, const char* flag);

// Whether binding HOST:PORT fails with EADDRINUSE right now (used to explain a failed listen).
bool AddressInUse(const std::string& address);

}  // namespace geodex::server
