// One request answered by cpp-httplib's routing on a worker: the request's bytes, which the
// connection loop has read whole (server/http/connection_loop.h), go to httplib as a Stream, and
// the answer goes back through the connection. httplib 0.11 is used for what it does well
// (parsing, routes, static files, ranges, chunked answers) and not for its connections: it
// gives each a thread from accept to close, reads with a per-read timeout only and queues
// without bound.
#ifndef MOTIONDB_SERVER_HTTP_HTTP_EXCHANGE_H_
#define MOTIONDB_SERVER_HTTP_HTTP_EXCHANGE_H_

#include <chrono>

#include <httplib.h>

#include "absl/strings/string_view.h"
#include "server/http/http_connection.h"

namespace motiondb::server {

// httplib's server with its routes, answering requests handed to it rather than accepting
// connections of its own (it never listens).
class HttpRouter : public httplib::Server {
 public:
  HttpRouter();
  // Answers `request` (head and body) on `connection`; `last` says the connection closes after
  // it (the answer says so). Returns whether the connection may carry another request.
  bool Answer(HttpConnection& connection, absl::string_view request, bool last,
              std::chrono::milliseconds write_stall_timeout);
  // Answers under way that stream their body (a chunked export) stop at their next piece.
  void StopStreaming();
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_HTTP_EXCHANGE_H_
