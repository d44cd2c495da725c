// The one shape of every gRPC handler: the call admitted by the gate (server/grpc/call_gate.h),
// then run with a stop that fires when the call ends (server/grpc/call_context.h), and its
// absl::Status told to the client once, a stop explained as the deadline's or the client's
// (server/grpc/status_conversion.h). What is left to a handler is what differs: convert the
// request (its service's *_conversion.h), call the application, convert the outcome.
#ifndef MOTIONDB_SERVER_GRPC_SERVE_H_
#define MOTIONDB_SERVER_GRPC_SERVE_H_

#include <functional>

#include <grpcpp/server_context.h>
#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "server/grpc/call_gate.h"

namespace motiondb::server {

// For SearchParams::should_stop and the like: true once the call has ended.
using ShouldStop = std::function<bool()>;

grpc::Status Serve(CallGate& gate, grpc::ServerContext* context,
                   const std::function<absl::Status(const ShouldStop& should_stop)>& call);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SERVE_H_
