#include "auth.h"

#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"

namespace geodex::server {
namespace {

// Equal strings compare in time that depends only on their lengths.
bool ConstantTimeEqual(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

}  // namespace

absl::StatusOr<std::vector<std::string>> ReadTokenFile(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    return absl::InvalidArgumentError(absl::StrCat("--auth_token_file ", path, ": cannot read"));
  std::vector<std::string> tokens;
  for (std::string line; std::getline(in, line);) {
    std::string token(absl::StripAsciiWhitespace(line));
    if (!token.empty() && token[0] != '#') tokens.push_back(token);
  }
  if (tokens.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("--auth_token_file ", path, ": no token in it"));
  }
  return tokens;
}

bool TokenAuthenticator::Allows(const grpc::CallbackServerContext& context) const {
  if (tokens_.empty()) return true;
  const auto& metadata = context.client_metadata();
  auto it = metadata.find("authorization");
  if (it == metadata.end()) return false;
  const std::string kBearer = "Bearer ";
  const std::string value(it->second.data(), it->second.size());
  if (value.size() <= kBearer.size() || value.compare(0, kBearer.size(), kBearer) != 0)
    return false;
  const std::string presented = value.substr(kBearer.size());
  bool ok = false;
  for (const std::string& token : tokens_) ok |= ConstantTimeEqual(presented, token);
  return ok;
}

grpc::Status UnauthenticatedStatus() {
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                      "missing or invalid bearer token (metadata \"authorization: Bearer TOKEN\")");
}

}  // namespace geodex::server
