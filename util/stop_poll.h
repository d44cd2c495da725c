// Stopping long work when its caller says so (a call's deadline or cancellation, a job being
// cancelled). A loop counts its work in units whose cost it knows (cells of a warp, frames of a
// clip) and asks the caller's stop function once per `work_per_poll` units: often enough that a
// stop is seen within about a millisecond of work, rarely enough that asking costs nothing
// measurable (docs/server-limits.md, "Deadlines and query length";
// bench/notes/2026-12-06-deadlines.md).
#ifndef MOTIONDB_UTIL_STOP_POLL_H_
#define MOTIONDB_UTIL_STOP_POLL_H_

#include <cstdint>
#include <functional>

namespace motiondb {

// Not thread-safe: one per thread; the stop function it asks may be shared, and must then be
// safe to call from several threads at once.
class StopPoll {
 public:
  // Never stops.
  StopPoll() = default;
  // `should_stop` (empty: never stop) must outlive the poll. It is asked at the first Done(),
  // so that work already stopped does none of itself, then once per `work_per_poll` units.
  StopPoll(const std::function<bool()>& should_stop, int64_t work_per_poll)
      : should_stop_(should_stop ? &should_stop : nullptr),
        work_per_poll_(work_per_poll),
        pending_(work_per_poll) {}

  // Counts `work` more units about to be done; true once the stop function has said stop, and
  // from then on.
  bool Done(int64_t work) {
    if (should_stop_ == nullptr || stopped_) return stopped_;
    pending_ += work;
    if (pending_ < work_per_poll_) return false;
    pending_ = 0;
    stopped_ = (*should_stop_)();
    return stopped_;
  }
  bool stopped() const { return stopped_; }

 private:
  const std::function<bool()>* should_stop_ = nullptr;
  int64_t work_per_poll_ = 1;
  int64_t pending_ = 0;
  bool stopped_ = false;
};

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_STOP_POLL_H_
