#include "server/grpc/stream_watchdog.h"

#include <grpc/grpc.h>

#include <algorithm>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/grpc/request_logger.h"

namespace motiondb::server {

using Clock = std::chrono::steady_clock;

struct StreamWatchdog::Entry {
  grpc::ServerContext* context;
  std::string peer;  // read at the start: a cancelled call's peer is "unknown"
  Clock::time_point start;
  std::atomic<Clock::rep> last_touch;  // Clock ticks
  std::atomic<int64_t> bytes = 0;
  std::atomic<bool> ended = false;
  std::string reason;  // why it was ended; written before `ended` is set
};

StreamWatchdog::StreamWatchdog(const StreamLimits& limits) : limits_(limits) {
  if (limits_.idle_timeout.count() > 0 || limits_.min_bytes_per_s > 0) {
    thread_ = std::thread([this] { Run(); });
  }
}

StreamWatchdog::~StreamWatchdog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  if (thread_.joinable()) thread_.join();
}

StreamWatchdog::Watch StreamWatchdog::Start(grpc::ServerContext* context) {
  auto entry = std::make_shared<Entry>();
  entry->context = context;
  entry->peer = context->peer();
  entry->start = Clock::now();
  entry->last_touch = entry->start.time_since_epoch().count();
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.push_back(entry);
  return Watch(this, std::move(entry));
}

StreamWatchdog::Watch::Watch(Watch&& other) noexcept
    : watchdog_(std::exchange(other.watchdog_, nullptr)), entry_(std::move(other.entry_)) {}

StreamWatchdog::Watch::~Watch() {
  if (watchdog_ == nullptr) return;
  // Under the watchdog's mutex, so that it never cancels a call whose handler has returned.
  std::lock_guard<std::mutex> lock(watchdog_->mutex_);
  std::erase(watchdog_->entries_, entry_);
}

void StreamWatchdog::Watch::Touch(size_t bytes) {
  entry_->bytes.fetch_add(static_cast<int64_t>(bytes), std::memory_order_relaxed);
  entry_->last_touch.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
}

absl::Status StreamWatchdog::Watch::Status() const {
  if (!entry_->ended) return absl::OkStatus();
  return absl::DeadlineExceededError(entry_->reason);
}

void StreamWatchdog::Run() {
  // A few looks per timeout (at least one a second for the rate): an idle stream ends between 1
  // and 1.25 timeouts after its last message.
  auto period = std::chrono::milliseconds(1000);
  if (limits_.idle_timeout.count() > 0) {
    period = std::clamp(limits_.idle_timeout / 4, std::chrono::milliseconds(10), period);
  }
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_.wait_for(lock, period, [this] { return stopping_; })) {
    const Clock::time_point now = Clock::now();
    for (const std::shared_ptr<Entry>& entry : entries_) {
      if (entry->ended) continue;
      const Clock::duration idle =
          now -
          Clock::time_point(Clock::duration(entry->last_touch.load(std::memory_order_relaxed)));
      const double elapsed_s = std::chrono::duration<double>(now - entry->start).count();
      const int64_t bytes = entry->bytes.load(std::memory_order_relaxed);
      if (limits_.idle_timeout.count() > 0 && idle > limits_.idle_timeout) {
        entry->reason =
            absl::StrCat("the stream sent nothing for ",
                         std::chrono::duration<double>(limits_.idle_timeout).count(),
                         " s, the most this server waits (--stream-idle-timeout-s); it was ended");
      } else if (limits_.min_bytes_per_s > 0 && now - entry->start > limits_.rate_grace &&
                 static_cast<double>(bytes) < limits_.min_bytes_per_s * elapsed_s) {
        entry->reason = absl::StrFormat(
            "the stream sent %d bytes in %.0f s, slower than the %.0f KiB/s this server takes "
            "(--min-upload-kbps); it was ended",
            bytes, elapsed_s, limits_.min_bytes_per_s / 1024);
      } else {
        continue;
      }
      entry->ended = true;
      // Ended with the reason, which the client is told (TryCancel would tell it "Cancelled").
      grpc_call_cancel_with_status(entry->context->c_call(), GRPC_STATUS_DEADLINE_EXCEEDED,
                                   entry->reason.c_str(), nullptr);
      LogLine(absl::StrCat("ended a stream from ", entry->peer, ": ", entry->reason));
    }
  }
}

}  // namespace motiondb::server
