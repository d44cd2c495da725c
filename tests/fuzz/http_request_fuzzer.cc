// libFuzzer target: the HTTP face's connections (server/http/connection_loop.h), fed raw bytes
// over a real TCP connection to a real server in this process (over a small real library,
// tests/fuzz/fuzz_library.h): request heads of every shape, bodies and their lengths, several
// requests pipelined, a connection cut anywhere. The server's limits are lowered (heads, the
// uploads' budget, the request timeout) so that inputs reach them. Every answer must be a
// well-formed HTTP/1.1 status line, none a 5xx but 501, 503 (a full line) or 504 (a call past its
// deadline); nothing may crash, hang or trip a sanitizer. Writes are refused by a read-only token,
// so that every input meets the same library.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "server/grpc/motiondb_server.h"
#include "server/http/http_server.h"
#include "tests/fuzz/fuzz_library.h"

namespace {

struct Servers {
  std::unique_ptr<motiondb::server::MotionDbServer> grpc;
  std::unique_ptr<motiondb::server::HttpServer> http;
};

Servers& TheServers() {
  static Servers* const servers = [] {
    auto made = new Servers;
    motiondb::server::ServerOptions options;
    options.db_path = motiondb::fuzz::TheFuzzLibrary().path;
    options.listen = "127.0.0.1:0";
    options.log_requests = false;
    options.auth_tokens = {{motiondb::TokenScope::kRead, "fuzz-token"}};
    options.uploads.max_buffered_bytes = 1 << 20;
    auto grpc = motiondb::server::MotionDbServer::Start(options);
    if (!grpc.ok()) {
      std::fprintf(stderr, "http request fuzzer: %s\n", grpc.status().ToString().c_str());
      std::abort();
    }
    made->grpc = *std::move(grpc);
    motiondb::server::HttpOptions http;
    http.listen = "127.0.0.1:0";
    http.loop.head_timeout = std::chrono::milliseconds(200);
    http.loop.idle_timeout = std::chrono::milliseconds(200);
    http.call_timeout_s = 0.2;
    auto started = motiondb::server::HttpServer::Start(http, *made->grpc);
    if (!started.ok()) {
      std::fprintf(stderr, "http request fuzzer: %s\n", started.status().ToString().c_str());
      std::abort();
    }
    made->http = *std::move(started);
    return made;
  }();
  return *servers;
}

// Everything the server sends until it closes the connection; aborts when it does not within
// 10 s (every wait of the server's is far shorter).
std::string Exchange(int port, const uint8_t* data, size_t size) {
  const int socket = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(socket, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    std::perror("connect");
    std::abort();
  }
  // A write the server refuses to read on (it answered and closed) is no finding.
  for (size_t sent = 0; sent < size;) {
    const ssize_t wrote = ::send(socket, data + sent, size - sent, MSG_NOSIGNAL);
    if (wrote <= 0) break;
    sent += static_cast<size_t>(wrote);
  }
  ::shutdown(socket, SHUT_WR);
  std::string answer;
  char buffer[16384];
  for (;;) {
    pollfd watched{socket, POLLIN, 0};
    if (::poll(&watched, 1, 10'000) <= 0) {
      std::fprintf(stderr, "the server neither answered nor closed within 10 s\n");
      std::abort();
    }
    const ssize_t got = ::recv(socket, buffer, sizeof(buffer), 0);
    if (got <= 0) break;
    answer.append(buffer, static_cast<size_t>(got));
  }
  ::close(socket);
  return answer;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Servers& servers = TheServers();
  const std::string answer = Exchange(servers.http->port(), data, size);
  static const std::regex status_line("HTTP/1\\.1 ([0-9]{3}) [^\r\n]*\r\n");
  for (auto it = std::sregex_iterator(answer.begin(), answer.end(), status_line);
       it != std::sregex_iterator(); ++it) {
    const int status = std::stoi((*it)[1]);
    if (status >= 500 && status != 501 && status != 503 && status != 504) {
      std::fprintf(stderr, "answered %d:\n%s\n", status, answer.c_str());
      std::abort();
    }
  }
  if (!answer.empty() && answer.rfind("HTTP/1.1 ", 0) != 0) {
    std::fprintf(stderr, "an answer that is not HTTP/1.1:\n%s\n", answer.c_str());
    std::abort();
  }
  return 0;
}
