// Indices [0, count) handed out one at a time, in increasing order, to the threads of a
// parallel loop (ParallelFor, ThreadTeam) until one fails; the lowest failed index's failure is
// kept, so that the outcome does not depend on timing. Thread-safe.
#ifndef MOTIONDB_UTIL_INTERNAL_INDEX_HANDOUT_H_
#define MOTIONDB_UTIL_INTERNAL_INDEX_HANDOUT_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <utility>

#include "absl/status/status.h"

namespace motiondb {

class IndexHandout {
 public:
  explicit IndexHandout(int64_t count) : count_(count) {}

  // Calls body(index, thread) for the indices this thread is handed, until none is left or a
  // call failed.
  void Run(int thread, const std::function<absl::Status(int64_t index, int thread)>& body) {
    for (int64_t i = next_++; i < count_ && !failed_.load(std::memory_order_relaxed); i = next_++) {
      absl::Status status = body(i, thread);
      if (status.ok()) continue;
      const std::lock_guard<std::mutex> lock(mutex_);
      if (i < failed_index_) {
        failed_index_ = i;
        failure_ = std::move(status);
      }
      failed_ = true;
    }
  }

  // Once every Run has returned.
  absl::Status failure() const { return failure_; }

 private:
  const int64_t count_;
  std::atomic<int64_t> next_{0};
  std::atomic<bool> failed_{false};
  std::mutex mutex_;
  int64_t failed_index_ = count_;  // the lowest failed index, under `mutex_`
  absl::Status failure_;
};

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_INTERNAL_INDEX_HANDOUT_H_
