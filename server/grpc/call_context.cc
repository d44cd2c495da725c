#include "server/grpc/call_context.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"

namespace motiondb::server {
namespace {

bool DeadlinePassed(const grpc::ServerContext* context) {
  return std::chrono::system_clock::now() > context->deadline();
}

}  // namespace

std::function<bool()> StopWhenCallEnds(const grpc::ServerContext* context) {
  // The deadline is compared here as well as through IsCancelled(): the core marks the call
  // cancelled when its deadline timer fires, which may lag behind the clock.
  return [context] { return context->IsCancelled() || DeadlinePassed(context); };
}

absl::Status ExplainStop(absl::Status status, const grpc::ServerContext* context) {
  if (!absl::IsCancelled(status)) return status;
  if (DeadlinePassed(context)) {
    return absl::DeadlineExceededError(absl::StrCat("deadline exceeded (", status.message(), ")"));
  }
  return absl::CancelledError(absl::StrCat("cancelled by the client (", status.message(), ")"));
}

absl::Time WaitDeadlineOf(const grpc::ServerContext& context, absl::Duration otherwise) {
  const auto deadline = context.deadline();
  if (deadline == std::chrono::system_clock::time_point::max()) return absl::Now() + otherwise;
  const absl::Time end = absl::FromChrono(deadline);
  const absl::Duration left = std::max(end - absl::Now(), absl::ZeroDuration());
  return end - std::min(left / 10, absl::Seconds(1));
}

}  // namespace motiondb::server
