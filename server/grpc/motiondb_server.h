// The motiondb server, assembled: the database, the resident indices loaded from its cached
// projections, the four motiondb.v1 services, the standard health service, server reflection,
// the request log and the port's credentials (TLS, bearer token).
#ifndef MOTIONDB_SERVER_GRPC_MOTIONDB_SERVER_H_
#define MOTIONDB_SERVER_GRPC_MOTIONDB_SERVER_H_

#include <chrono>
#include <memory>

#include <grpcpp/channel.h>
#include <grpcpp/server.h>

#include "absl/status/statusor.h"
#include "server/grpc/access_control.h"
#include "server/grpc/request_logger.h"
#include "server/grpc/server_options.h"
#include "server/metrics/server_metrics.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

class MotionDbServer {
 public:
  // Opens the database, loads every space's index, and starts serving. Errors name what failed
  // (the database, a space, the port).
  static absl::StatusOr<std::unique_ptr<MotionDbServer>> Start(const ServerOptions& options);
  ~MotionDbServer();

  // The port listened on (useful with port 0 in --listen).
  int port() const { return port_; }
  // Stops accepting calls, lets running ones finish until `deadline`, then cancels the rest.
  void Shutdown(std::chrono::system_clock::time_point deadline);
  // Blocks until Shutdown() has completed.
  void Wait();
  // Readiness: what the health service (and so /readyz) answers for the server as a whole,
  // SERVING from the start; a cluster node is ready only while registered. Call it before
  // Shutdown(), which turns it NOT_SERVING for good.
  void SetServing(bool serving);

  // A channel to the same services inside this process (the HTTP face's): no network, no
  // credentials (the caller checks the token), the calls logged and counted as any other, with
  // the caller's x-motiondb-http-peer metadata as their peer. Calls fail with UNAVAILABLE once
  // Shutdown() has begun.
  std::shared_ptr<grpc::Channel> InProcessChannel() const;
  // Whether the port takes a new connection now (server/net/listener.h): false while the
  // process is out of descriptors or every connection place is taken; readiness says so.
  bool accepting() const;
  ServerMetrics& metrics() const;
  // What the uploads in progress hold: gRPC ingests and the HTTP face's request bodies share it.
  UploadBudget& upload_budget() const;
  // Who may call what; the HTTP face decides with it too.
  AccessControl& access() const;
  RequestLog& request_log() const;
  const ServerOptions& options() const;

 private:
  struct State;
  explicit MotionDbServer(std::unique_ptr<State> state);

  std::unique_ptr<State> state_;
  int port_ = 0;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_MOTIONDB_SERVER_H_
