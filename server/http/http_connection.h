// One client connection of the HTTP face: its socket, TLS on it when the server has a
// certificate, and the bytes read and not yet answered. The connection loop reads it without
// blocking (server/http/connection_loop.h); a worker writes its answer, waiting while the client
// is slow to take it. One thread at a time: the loop hands it to a worker and gets it back.
#ifndef MOTIONDB_SERVER_HTTP_HTTP_CONNECTION_H_
#define MOTIONDB_SERVER_HTTP_HTTP_CONNECTION_H_

#include <openssl/ssl.h>
#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <string>

#include "absl/strings/string_view.h"
#include "server/net/listener.h"

namespace motiondb::server {

class HttpConnection {
 public:
  // `tls`: the server's context, or null for plain HTTP.
  HttpConnection(AcceptedConnection accepted, SSL_CTX* tls);
  ~HttpConnection();
  HttpConnection(const HttpConnection&) = delete;
  HttpConnection& operator=(const HttpConnection&) = delete;

  enum class Io {
    kDone,       // the handshake is done, or bytes arrived
    kWantRead,   // nothing more until the socket is readable
    kWantWrite,  // (TLS) nothing more until the socket is writable
    kClosed,     // the client closed its side
    kFailed,     // a socket or TLS error
  };

  // Advances the TLS handshake (kDone at once without TLS).
  Io Handshake();
  // Reads what is there, without blocking, until `buffer()` holds `up_to` bytes.
  Io Read(size_t up_to);
  // Writes what the socket takes now, without blocking: a short refusal. -1 on an error.
  ssize_t TryWrite(absl::string_view data);
  // Writes all of `data`, waiting while the client is slow: false on an error, or when no byte
  // could be written for `stall_timeout`, or once Cut() was called.
  bool Write(absl::string_view data, std::chrono::milliseconds stall_timeout);
  // Waits until a byte can be written, at most `timeout`.
  bool Writable(std::chrono::milliseconds timeout) const;
  // Ends the connection's traffic from another thread (shutdown(2)): a worker blocked writing
  // to a client that reads nothing returns at once. The socket stays open until destroyed.
  void Cut();

  std::string& buffer() { return buffer_; }
  int socket() const { return accepted_.socket.get(); }
  const std::string& peer_address() const { return accepted_.peer_address; }
  int peer_port() const { return accepted_.peer_port; }
  // "ADDRESS:PORT", for logs.
  std::string peer() const;
  bool tls() const { return ssl_ != nullptr; }

 private:
  AcceptedConnection accepted_;
  SSL* ssl_ = nullptr;
  std::string buffer_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_HTTP_CONNECTION_H_
