#include "server/grpc/serve.h"

#include "server/grpc/call_context.h"
#include "server/grpc/status_conversion.h"

namespace motiondb::server {

grpc::Status Serve(CallGate& gate, grpc::ServerContext* context,
                   const std::function<absl::Status(const ShouldStop& should_stop)>& call) {
  return gate.Run(
      context, [&] { return ToGrpcStatus(ExplainStop(call(StopWhenCallEnds(context)), context)); });
}

}  // namespace motiondb::server
