// libFuzzer target: geodexd's HTTP/JSON port (server/http_edge.h) on arbitrary bytes. One server
// runs in-process with the built-in samples and its HTTP port on 127.0.0.1:0 (small work budgets);
// each input is sent as it is on a new connection, its write side then closed, and the answer read
// to the end. civetweb's request parsing, the routes, the JSON mapping, the upload path, the
// error mapping and the queries behind them are all reached. Nothing may crash, hang or grow: an
// answer, when there is one, is an HTTP status line.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "geodex_server.h"

namespace {

geodex::server::GeodexServer* Server() {
  static geodex::server::GeodexServer* server = [] {
    geodex::server::ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.samples = true;
    options.pool_threads = 1;
    options.quick_threads = 1;
    options.background_solves = false;
    options.limits.max_windows = 100000;
    options.limits.max_steiner_points = 20000;
    options.limits.max_sources = 64;
    options.limits.max_targets = 64;
    options.limits.max_levels = 16;
    options.limits.max_output_values = 100000;
    options.limits.max_upload_bytes = 1 << 20;
    options.http.listen = "127.0.0.1:0";
    options.http.threads = 2;
    options.http.max_response_bytes = 1 << 20;
    auto started = geodex::server::GeodexServer::Start(options);
    if (!started.ok()) {
      fprintf(stderr, "cannot start: %s\n", std::string(started.status().message()).c_str());
      abort();
    }
    return started->release();
  }();
  return server;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const int port = Server()->http_port();
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return 0;
  timeval limit{10, 0};  // the server answers or closes well before: a hang fails the input
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    close(fd);
    return 0;
  }
  for (size_t sent = 0; sent < size;) {
    const ssize_t n = send(fd, data + sent, size - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  shutdown(fd, SHUT_WR);
  std::string answer;
  char buffer[65536];
  for (ssize_t n; (n = recv(fd, buffer, sizeof buffer, 0)) > 0;) answer.append(buffer, n);
  const bool timed_out = errno == EAGAIN || errno == EWOULDBLOCK;
  close(fd);
  if (timed_out && answer.empty()) {
    fprintf(stderr, "no answer within 10 s\n");
    __builtin_trap();
  }
  if (!answer.empty() && answer.compare(0, 5, "HTTP/") != 0) {
    fprintf(stderr, "not an HTTP answer: %.80s\n", answer.c_str());
    __builtin_trap();
  }
  return 0;
}
