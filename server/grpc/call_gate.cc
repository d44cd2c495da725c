#include "server/grpc/call_gate.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "absl/cleanup/cleanup.h"
#include "absl/strings/str_cat.h"

namespace motiondb::server {
namespace {

// How often a waiting call looks whether its client cancelled (gRPC does not wake it).
constexpr std::chrono::milliseconds kCancelPoll{20};

}  // namespace

grpc::Status CallGate::Allowed(const grpc::ServerContext* context) const {
  return access_ == nullptr ? grpc::Status::OK : access_->VerdictOf(context).status;
}

grpc::Status CallGate::Run(const grpc::ServerContext* context,
                           const std::function<grpc::Status()>& call) {
  if (grpc::Status allowed = Allowed(context); !allowed.ok()) return allowed;
  if (max_running_ <= 0) return call();
  grpc::Status refusal;
  if (!Enter(context, &refusal)) return refusal;
  const absl::Cleanup leave = [this] { Leave(); };  // also when the call throws
  return call();
}

bool CallGate::Enter(const grpc::ServerContext* context, grpc::Status* refusal) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (running_ < max_running_ && line_.empty()) {
    ++running_;
    return true;
  }
  if (static_cast<int>(line_.size()) >= max_waiting_) {
    *refusal = grpc::Status(
        grpc::StatusCode::RESOURCE_EXHAUSTED,
        absl::StrCat("the server is busy: ", running_, " calls running and ", line_.size(),
                     " waiting, the most it holds (--threads ", max_running_, "); retry later"));
    return false;
  }
  const uint64_t ticket = next_ticket_++;
  line_.push_back(ticket);
  const auto deadline = context->deadline();
  while (!(line_.front() == ticket && running_ < max_running_)) {
    const auto now = std::chrono::system_clock::now();
    const bool expired = now >= deadline;
    if (expired || context->IsCancelled()) {
      line_.erase(std::find(line_.begin(), line_.end(), ticket));
      freed_.notify_all();  // the next in line may be first now
      *refusal = expired ? grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                                        "the deadline passed while the call waited its turn")
                         : grpc::Status(grpc::StatusCode::CANCELLED, "cancelled while waiting");
      return false;
    }
    freed_.wait_until(lock,
                      std::min<std::chrono::system_clock::time_point>(deadline, now + kCancelPoll));
  }
  line_.pop_front();
  ++running_;
  freed_.notify_all();  // the next in line may run too, when slots are free
  return true;
}

int CallGate::waiting() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(line_.size());
}

void CallGate::Leave() {
  std::lock_guard<std::mutex> lock(mutex_);
  --running_;
  freed_.notify_all();
}

}  // namespace motiondb::server
