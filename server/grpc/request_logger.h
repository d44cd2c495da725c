// One line per call on stderr: time, method, status code name, latency and peer, e.g.
//   2024-05-01T12:00:00.123Z /motiondb.v1.SearchService/Search OK 3.21ms ipv4:127.0.0.1:53422
// A gRPC server interceptor sees every call that reaches a service (ours, health, reflection);
// calls refused before that (a bad token) are logged by server/credentials.cc.
#ifndef MOTIONDB_SERVER_GRPC_REQUEST_LOGGER_H_
#define MOTIONDB_SERVER_GRPC_REQUEST_LOGGER_H_

#include <grpcpp/support/server_interceptor.h>
#include <grpcpp/support/status.h>

#include "absl/strings/string_view.h"

namespace motiondb::server {

// Writes one line in a single write(2), so that lines of concurrent calls do not interleave.
void LogRequest(absl::string_view method, grpc::StatusCode code, double latency_ms,
                absl::string_view peer);

// Writes a free-form line (startup, shutdown) with the same time stamp.
void LogLine(absl::string_view text);

class RequestLoggerFactory : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_REQUEST_LOGGER_H_
