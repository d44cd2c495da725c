#include "server/http/http_connection.h"

#include <openssl/err.h>
#include <poll.h>
#include <sys/socket.h>

#include <cerrno>

#include "absl/strings/str_cat.h"

namespace motiondb::server {
namespace {

// Bytes asked of the socket at a time.
constexpr size_t kReadPiece = 16 << 10;

HttpConnection::Io TlsOutcome(SSL* ssl, int result) {
  switch (SSL_get_error(ssl, result)) {
    case SSL_ERROR_WANT_READ:
      return HttpConnection::Io::kWantRead;
    case SSL_ERROR_WANT_WRITE:
      return HttpConnection::Io::kWantWrite;
    case SSL_ERROR_ZERO_RETURN:
      return HttpConnection::Io::kClosed;
    default:
      ERR_clear_error();  // the thread's error queue must not carry it to another connection
      return HttpConnection::Io::kFailed;
  }
}

bool Wait(int socket, short events, std::chrono::milliseconds timeout) {
  pollfd watched{socket, events, 0};
  const int ready = ::poll(&watched, 1, static_cast<int>(timeout.count()));
  return ready > 0 && (watched.revents & (POLLERR | POLLNVAL)) == 0 &&
         (watched.revents & events) != 0;
}

}  // namespace

HttpConnection::HttpConnection(AcceptedConnection accepted, SSL_CTX* tls)
    : accepted_(std::move(accepted)) {
  if (tls != nullptr) {
    ssl_ = SSL_new(tls);
    if (ssl_ != nullptr) {
      SSL_set_fd(ssl_, accepted_.socket.get());
      SSL_set_accept_state(ssl_);
      SSL_set_mode(ssl_, SSL_MODE_ENABLE_PARTIAL_WRITE | SSL_MODE_ACCEPT_MOVING_WRITE_BUFFER);
    }
  }
}

HttpConnection::~HttpConnection() {
  if (ssl_ != nullptr) SSL_free(ssl_);  // no close_notify: the peer may be gone or hostile
}

std::string HttpConnection::peer() const {
  return absl::StrCat(accepted_.peer_address, ":", accepted_.peer_port);
}

HttpConnection::Io HttpConnection::Handshake() {
  if (ssl_ == nullptr) return Io::kDone;
  const int result = SSL_do_handshake(ssl_);
  return result == 1 ? Io::kDone : TlsOutcome(ssl_, result);
}

HttpConnection::Io HttpConnection::Read(size_t up_to) {
  bool any = false;
  while (buffer_.size() < up_to) {
    const size_t piece = std::min(kReadPiece, up_to - buffer_.size());
    const size_t old_size = buffer_.size();
    buffer_.resize(old_size + piece);
    ssize_t got = 0;
    Io blocked = Io::kWantRead;
    if (ssl_ != nullptr) {
      const int result = SSL_read(ssl_, buffer_.data() + old_size, static_cast<int>(piece));
      if (result <= 0) blocked = TlsOutcome(ssl_, result);
      got = result;
    } else {
      got = ::recv(socket(), buffer_.data() + old_size, piece, 0);
      if (got == 0) blocked = Io::kClosed;
      if (got < 0) {
        blocked =
            errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? Io::kWantRead : Io::kFailed;
      }
    }
    buffer_.resize(old_size + static_cast<size_t>(std::max<ssize_t>(got, 0)));
    if (got <= 0) return any && blocked != Io::kFailed ? Io::kDone : blocked;
    any = true;
  }
  return Io::kDone;
}

ssize_t HttpConnection::TryWrite(absl::string_view data) {
  if (ssl_ != nullptr) {
    const int result = SSL_write(ssl_, data.data(), static_cast<int>(data.size()));
    if (result <= 0) TlsOutcome(ssl_, result);
    return result > 0 ? result : -1;
  }
  return ::send(socket(), data.data(), data.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

bool HttpConnection::Writable(std::chrono::milliseconds timeout) const {
  return Wait(socket(), POLLOUT, timeout);
}

bool HttpConnection::Write(absl::string_view data, std::chrono::milliseconds stall_timeout) {
  while (!data.empty()) {
    short wanted = POLLOUT;
    ssize_t written = 0;
    if (ssl_ != nullptr) {
      const int result = SSL_write(ssl_, data.data(), static_cast<int>(data.size()));
      written = result;
      if (result <= 0) {
        const Io outcome = TlsOutcome(ssl_, result);
        if (outcome != Io::kWantRead && outcome != Io::kWantWrite) return false;
        wanted = outcome == Io::kWantRead ? POLLIN : POLLOUT;  // a renegotiation
      }
    } else {
      written = ::send(socket(), data.data(), data.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      if (written < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return false;
    }
    if (written > 0) {
      data.remove_prefix(static_cast<size_t>(written));
      continue;
    }
    if (!Wait(socket(), wanted, stall_timeout)) return false;
  }
  return true;
}

void HttpConnection::Cut() { ::shutdown(socket(), SHUT_RDWR); }

}  // namespace motiondb::server
