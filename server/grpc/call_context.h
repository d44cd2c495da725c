// Deadlines and cancellation of a gRPC call, as the engine's long loops understand them.
#ifndef MOTIONDB_SERVER_GRPC_CALL_CONTEXT_H_
#define MOTIONDB_SERVER_GRPC_CALL_CONTEXT_H_

#include <functional>

#include <grpcpp/server_context.h>

#include "absl/status/status.h"
#include "absl/time/time.h"

namespace motiondb::server {

// For SearchParams::should_stop and the like: true once the client cancelled or the call's
// deadline passed. Cheap enough to poll every few thousand iterations.
std::function<bool()> StopWhenCallEnds(const grpc::ServerContext* context);

// The engine reports a stop as CANCELLED; when the deadline is what ended the call, the client
// is told DEADLINE_EXCEEDED. Other statuses pass through.
absl::Status ExplainStop(absl::Status status, const grpc::ServerContext* context);

// When what waits on another service (a cluster node's etcd reads) gives up: a tenth of the
// time left (at most a second) before the call's deadline, so that the call still answers, saying
// which service it waited for, rather than the caller seeing only its deadline pass. A call
// without a deadline is given `otherwise` from now.
absl::Time WaitDeadlineOf(const grpc::ServerContext& context,
                          absl::Duration otherwise = absl::Seconds(10));

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_CALL_CONTEXT_H_
