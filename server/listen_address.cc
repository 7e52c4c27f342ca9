#include "listen_address.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace geodex::server {
namespace {

// Splits HOST:PORT ("[v6]:port" too); false when there is no port.
bool SplitHostPort(const std::string& address, std::string* host, std::string* port) {
  const size_t colon = address.rfind(':');
  if (colon == std::string::npos) return false;
  *host = address.substr(0, colon);
  *port = address.substr(colon + 1);
  if (host->find(':') != std::string::npos) {  // IPv6: must be bracketed
    if (host->size() < 2 || host->front() != '[' || host->back() != ']') return false;
    *host = host->substr(1, host->size() - 2);
  }
  return true;
}

}  // namespace

absl::Status ValidateListenAddress(const std::string& address, const char* flag) {
  if (absl::StartsWith(address, "unix:") || absl::StartsWith(address, "unix-abstract:")) {
    return absl::OkStatus();
  }
  std::string host, port;
  bool ok = SplitHostPort(address, &host, &port) && !port.empty() && port.size() <= 5;
  for (char c : port) ok = ok && absl::ascii_isdigit(static_cast<unsigned char>(c));
  if (ok) ok = std::atoi(port.c_str()) <= 65535;
  if (!ok) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--", flag, "=", address,
        ": expected HOST:PORT with an explicit port (0 picks a free one), an IPv6 host in "
        "brackets ([::1]:50051), or unix:PATH"));
  }
  return absl::OkStatus();
}

bool AddressInUse(const std::string& address) {
  std::string host, port;
  if (!SplitHostPort(address, &host, &port) || port == "0") return false;
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.empty() ? nullptr : host.c_str(), port.c_str(), &hints, &found) != 0) {
    return false;
  }
  bool in_use = false;
  for (addrinfo* a = found; a != nullptr && !in_use; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);  // as gRPC and civetweb do
    if (bind(fd, a->ai_addr, a->ai_addrlen) != 0 && errno == EADDRINUSE) in_use = true;
    close(fd);
  }
  freeaddrinfo(found);
  return in_use;
}

}  // namespace geodex::server
