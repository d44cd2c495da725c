#include "server/http/http_exchange.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstring>
#include <string>

namespace motiondb::server {
namespace {

// httplib writes an answer's status line, each header and the body apart: gathered up to this
// many bytes, they leave in one write (and one TLS record) instead of a packet each.
constexpr size_t kWriteGather = 16 << 10;

// httplib's view of one request: reads come from the bytes the loop read, writes go to the
// connection.
class RequestStream : public httplib::Stream {
 public:
  RequestStream(HttpConnection& connection, absl::string_view request,
                std::chrono::milliseconds stall_timeout)
      : connection_(connection), request_(request), stall_timeout_(stall_timeout) {}

  bool is_readable() const override { return !request_.empty(); }
  bool is_writable() const override {
    return failed_ ? false : connection_.Writable(stall_timeout_);
  }

  ssize_t read(char* ptr, size_t size) override {
    const size_t count = std::min(size, request_.size());
    if (count == 0) return -1;  // httplib never asks past the request it was given
    std::memcpy(ptr, request_.data(), count);
    request_.remove_prefix(count);
    return static_cast<ssize_t>(count);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (failed_) return -1;
    if (pending_.size() + size < kWriteGather) {
      pending_.append(ptr, size);
      return static_cast<ssize_t>(size);
    }
    // A large piece (a file, an export's chunk) goes as it is, after what was gathered.
    if (!Flush()) return -1;
    failed_ = !connection_.Write(absl::string_view(ptr, size), stall_timeout_);
    return failed_ ? -1 : static_cast<ssize_t>(size);
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = connection_.peer_address();
    port = connection_.peer_port();
  }

  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    ip.clear();
    port = 0;
    if (getsockname(connection_.socket(), reinterpret_cast<sockaddr*>(&address), &length) != 0) {
      return;
    }
    char text[INET6_ADDRSTRLEN] = {};
    if (address.ss_family == AF_INET) {
      const auto& v4 = reinterpret_cast<const sockaddr_in&>(address);
      inet_ntop(AF_INET, &v4.sin_addr, text, sizeof(text));
      port = ntohs(v4.sin_port);
    } else {
      const auto& v6 = reinterpret_cast<const sockaddr_in6&>(address);
      inet_ntop(AF_INET6, &v6.sin6_addr, text, sizeof(text));
      port = ntohs(v6.sin6_port);
    }
    ip = text;
  }

  socket_t socket() const override { return connection_.socket(); }

  // Writes what is gathered; false once a write has failed.
  bool Flush() {
    if (!failed_ && !pending_.empty()) failed_ = !connection_.Write(pending_, stall_timeout_);
    pending_.clear();
    return !failed_;
  }

 private:
  HttpConnection& connection_;
  absl::string_view request_;
  const std::chrono::milliseconds stall_timeout_;
  std::string pending_;
  bool failed_ = false;
};

// What httplib's content providers take for "the server is not shutting down": any descriptor
// number but INVALID_SOCKET (see StopStreaming).
constexpr socket_t kServing = 0;

}  // namespace

HttpRouter::HttpRouter() { svr_sock_ = kServing; }

bool HttpRouter::Answer(HttpConnection& connection, absl::string_view request, bool last,
                        std::chrono::milliseconds write_stall_timeout) {
  RequestStream stream(connection, request, write_stall_timeout);
  bool connection_closed = false;
  const bool answered = process_request(stream, last, connection_closed, nullptr);
  return stream.Flush() && answered && !connection_closed;
}

void HttpRouter::StopStreaming() { svr_sock_ = INVALID_SOCKET; }

}  // namespace motiondb::server
