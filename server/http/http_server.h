// The HTTP face of the server (server/grpc/motiondb_server.h assembles the gRPC one): the JSON
// API transcoded to the same services in-process (server/http/api_transcoder.h), GET /metrics
// (Prometheus), /healthz and /readyz, and the web UI's built files at /. HTTPS with the gRPC
// port's certificate and key when TLS is on; the API and the metrics need the gRPC token
// (Authorization: Bearer), the health routes as the gRPC health service does, the web UI's
// files never (they hold no data); requests from other web sites' pages are kept out
// (server/http/request_checks.h). The port and its connections are motiondb's
// (server/net/listener.h, server/http/connection_loop.h); cpp-httplib parses and routes each
// request once it has arrived whole (server/http/http_exchange.h).
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_HTTP_HTTP_SERVER_H_
#define MOTIONDB_SERVER_HTTP_HTTP_SERVER_H_

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/grpc/motiondb_server.h"
#include "server/http/connection_loop.h"
#include "server/net/connection_counter.h"

namespace motiondb::server {

struct HttpOptions {
  // host:port to serve HTTP on (--http); "off": no HTTP face. Port 0 picks a free one, logged.
  std::string listen = "127.0.0.1:8080";
  // The built web UI served at / (--web-root); empty: DefaultWebRoot().
  std::string web_root;
  // Host header names the face answers to beside IP addresses and localhost
  // (--http-allowed-hosts), or "*" for any (server/http/request_checks.h).
  std::vector<std::string> allowed_hosts;
  // Origins whose pages may call the API from their own (CORS, --http-cors-origins); none by
  // default, and then no Access-Control-* header is sent.
  std::vector<std::string> cors_origins;
  // An API call still running after this many seconds ends with 504 (DEADLINE_EXCEEDED), its
  // work stopped as a gRPC call's deadline stops it; HTTP clients send no deadline of their own
  // (--http-timeout-s).
  double call_timeout_s = 600;
  // Connections the HTTP port holds at once, in all (--http-max-connections) and from one
  // client address (--max-connections-per-peer).
  ConnectionLimits connections;
  // Timeouts, workers and their line (--http-threads, --http-max-waiting,
  // --http-request-timeout-s, --min-upload-kbps).
  HttpLoopOptions loop;
};

// The web/dist folder of the source tree this binary was built from.
std::string DefaultWebRoot();

class HttpServer {
 public:
  // Starts serving `server`'s HTTP face; it must outlive the HttpServer. UNAVAILABLE when the
  // address cannot be listened on, INVALID_ARGUMENT for a malformed one or a TLS certificate or
  // key that does not load.
  static absl::StatusOr<std::unique_ptr<HttpServer>> Start(const HttpOptions& options,
                                                           MotionDbServer& server);
  ~HttpServer();  // Stop()

  // Stops listening and reading requests: connections between requests close now (a slow
  // client's half-sent request with them); answers under way go on.
  void BeginStop();
  // BeginStop(), then lets answers under way finish until `deadline`, cuts the connections of
  // those still writing, and returns (idempotent).
  void Stop(std::chrono::steady_clock::time_point deadline);
  // The port listened on (useful with port 0).
  int port() const;

 private:
  struct State;
  explicit HttpServer(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_HTTP_SERVER_H_
