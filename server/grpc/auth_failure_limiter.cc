#include "server/grpc/auth_failure_limiter.h"

#include <algorithm>

namespace motiondb::server {

std::chrono::seconds AuthFailureLimiter::Blocked(absl::string_view address, Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = records_.find(address);
  if (found == records_.end() || found->second.failures < max_failures_) {
    return std::chrono::seconds(0);
  }
  const Clock::duration left = found->second.window_start + window_ - now;
  if (left <= Clock::duration::zero()) {
    records_.erase(found);
    return std::chrono::seconds(0);
  }
  return std::chrono::ceil<std::chrono::seconds>(left);
}

void AuthFailureLimiter::Fail(absl::string_view address, Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto found = records_.find(address);
  if (found == records_.end()) {
    if (records_.size() >= kMaxAddresses) {
      const auto oldest =
          std::min_element(records_.begin(), records_.end(), [](const auto& a, const auto& b) {
            return a.second.window_start < b.second.window_start;
          });
      records_.erase(oldest);
    }
    found = records_.emplace(std::string(address), Record{now, 0}).first;
  }
  Record& record = found->second;
  if (now - record.window_start >= window_) record = Record{now, 0};
  ++record.failures;
}

}  // namespace motiondb::server
