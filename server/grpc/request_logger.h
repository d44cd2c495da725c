// Every call, told once: a line on stderr (unless --quiet) and the server's metrics
// (server/metrics/server_metrics.h). A line holds the time, method, status code name, latency and
// peer:
//   2024-05-01T12:00:00.123Z /motiondb.v1.SearchService/Search OK 3.21ms ipv4:127.0.0.1:53422
// and, for a failure of the server's own (a full disk, say), the status message in quotes.
// A call of the HTTP face (server/http/) reaches the services in-process; its peer is shown as
// http:<the HTTP client's address> and its metrics carry face="http".
//
// A gRPC server interceptor sees every call that reaches a service (ours, health, reflection);
// calls refused before that (a bad token) are told by server/grpc/credentials.cc, and the HTTP
// face tells its own refusals.
#ifndef MOTIONDB_SERVER_GRPC_REQUEST_LOGGER_H_
#define MOTIONDB_SERVER_GRPC_REQUEST_LOGGER_H_

#include <grpcpp/support/server_interceptor.h>
#include <grpcpp/support/status.h>

#include "absl/strings/string_view.h"
#include "server/metrics/server_metrics.h"

namespace motiondb::server {

// The faces, as metrics label them.
inline constexpr absl::string_view kGrpcFace = "grpc";
inline constexpr absl::string_view kHttpFace = "http";
// The metadata by which the HTTP face names its client to the request log; believed only on
// in-process calls, which only the HTTP face makes.
inline constexpr char kHttpPeerMetadata[] = "x-motiondb-http-peer";

// Writes a free-form line (startup, shutdown) with the time stamp of the request lines, in a
// single write(2), so that lines of concurrent calls do not interleave.
void LogLine(absl::string_view text);

// Thread-safe.
class RequestLog {
 public:
  // `metrics` must outlive this.
  RequestLog(bool write_lines, ServerMetrics& metrics)
      : write_lines_(write_lines), metrics_(metrics) {}

  // A call of `method` on `face` that ended with `code` after `latency_ms`. Metrics name a
  // method that no service of this process has as "unknown" (a refused call's path is the
  // client's to choose). The line ends with `message`, quoted and escaped, for the codes of
  // the server's own conditions (RESOURCE_EXHAUSTED, INTERNAL, UNKNOWN, DATA_LOSS, UNAVAILABLE).
  void Record(absl::string_view face, absl::string_view method, grpc::StatusCode code,
              double latency_ms, absl::string_view peer, absl::string_view message = "");
  // The line alone, for what is no call of a method (the HTTP face's own refusals, counted in
  // its own metrics): `what` in the method's place and `outcome` in the code's, and `reason`
  // (quoted and escaped) when not empty.
  void WriteLine(absl::string_view what, absl::string_view outcome, double latency_ms,
                 absl::string_view peer, absl::string_view reason = "");

 private:
  const bool write_lines_;
  ServerMetrics& metrics_;
};

class RequestLoggerFactory : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit RequestLoggerFactory(RequestLog& log) : log_(log) {}
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override;

 private:
  RequestLog& log_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_REQUEST_LOGGER_H_
