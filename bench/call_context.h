// gRPC calls of the measurement programs: each bounded, so that a stuck call ends a run with an
// error rather than hanging it.
#ifndef MOTIONDB_BENCH_CALL_CONTEXT_H_
#define MOTIONDB_BENCH_CALL_CONTEXT_H_

#include <chrono>
#include <memory>

#include <grpcpp/client_context.h>

namespace motiondb::bench {

inline std::unique_ptr<grpc::ClientContext> ContextWithin(std::chrono::seconds limit) {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + limit);
  return context;
}

}  // namespace motiondb::bench

#endif  // MOTIONDB_BENCH_CALL_CONTEXT_H_
