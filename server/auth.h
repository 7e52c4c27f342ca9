#pragma once

// Bearer-token authentication of geodex.v1 calls. Every call must carry `authorization: Bearer
// TOKEN` metadata with one of the tokens of --auth_token_file; health and reflection stay open
// (they are other services), and so does the metrics endpoint. The check runs in the service's own
// handlers rather than in a grpc::AuthMetadataProcessor, which aborts the process on insecure
// credentials (gRPC 1.51): it works with and without TLS and can only ever answer UNAUTHENTICATED.

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "grpcpp/server_context.h"
#include "grpcpp/support/server_callback.h"

namespace geodex::server {

// One token per non-empty line (surrounding whitespace ignored; lines starting with # skipped).
// InvalidArgument when the file cannot be read or holds no token.
absl::StatusOr<std::vector<std::string>> ReadTokenFile(const std::string& path);

class TokenAuthenticator {
 public:
  // No tokens: every call is allowed.
  explicit TokenAuthenticator(std::vector<std::string> tokens) : tokens_(std::move(tokens)) {}
  bool enabled() const { return !tokens_.empty(); }
  // Whether the call's metadata carries a valid token (constant-time comparisons).
  bool Allows(const grpc::CallbackServerContext& context) const;

 private:
  std::vector<std::string> tokens_;
};

grpc::Status UnauthenticatedStatus();

// Reactors that only answer UNAUTHENTICATED (for streaming methods; unary ones use the context's
// default reactor).
template <typename Response>
class RejectedWriteReactor final : public grpc::ServerWriteReactor<Response> {
 public:
  explicit RejectedWriteReactor(const grpc::Status& status) { this->Finish(status); }
  void OnDone() override { delete this; }
};

template <typename Request>
class RejectedReadReactor final : public grpc::ServerReadReactor<Request> {
 public:
  explicit RejectedReadReactor(const grpc::Status& status) { this->Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace geodex::server
