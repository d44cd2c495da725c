// Failed authentications counted per client address: past `max_failures` within `window`, the
// address is refused without its token being looked at until the window has passed, so that
// guessing tokens is slow, on both faces together.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_GRPC_AUTH_FAILURE_LIMITER_H_
#define MOTIONDB_SERVER_GRPC_AUTH_FAILURE_LIMITER_H_

#include <chrono>
#include <mutex>
#include <string>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/string_view.h"

namespace motiondb::server {

class AuthFailureLimiter {
 public:
  using Clock = std::chrono::steady_clock;

  // Addresses remembered at most; past it the one whose window began first is forgotten.
  static constexpr size_t kMaxAddresses = 10'000;

  AuthFailureLimiter(int max_failures, std::chrono::seconds window)
      : max_failures_(max_failures), window_(window) {}

  // How long `address` is still refused; zero when it may try.
  std::chrono::seconds Blocked(absl::string_view address, Clock::time_point now = Clock::now());
  // Counts a failure of `address`.
  void Fail(absl::string_view address, Clock::time_point now = Clock::now());

  int max_failures() const { return max_failures_; }

 private:
  struct Record {
    Clock::time_point window_start;
    int failures = 0;
  };

  const int max_failures_;
  const std::chrono::seconds window_;
  std::mutex mutex_;
  absl::flat_hash_map<std::string, Record> records_;  // guarded by mutex_
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_AUTH_FAILURE_LIMITER_H_
