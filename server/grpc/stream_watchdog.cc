#include "server/grpc/stream_watchdog.h"

#include <algorithm>
#include <string>

#include "absl/strings/str_cat.h"
#include "server/grpc/request_logger.h"

namespace motiondb::server {

using Clock = std::chrono::steady_clock;

struct StreamWatchdog::Entry {
  grpc::ServerContext* context;
  std::string peer;                    // read at the start: a cancelled call's peer is "unknown"
  std::atomic<Clock::rep> last_touch;  // Clock ticks
  std::atomic<bool> ended = false;
};

StreamWatchdog::StreamWatchdog(std::chrono::milliseconds idle_timeout)
    : idle_timeout_(idle_timeout) {
  if (idle_timeout_.count() > 0) thread_ = std::thread([this] { Run(); });
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
  entry->last_touch = Clock::now().time_since_epoch().count();
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

void StreamWatchdog::Watch::Touch() {
  entry_->last_touch.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
}

absl::Status StreamWatchdog::Watch::Status() const {
  if (!entry_->ended) return absl::OkStatus();
  return absl::DeadlineExceededError(
      absl::StrCat("the stream sent nothing for ",
                   std::chrono::duration<double>(watchdog_->idle_timeout_).count(),
                   " s, the most this server waits (--stream-idle-timeout-s); it was ended"));
}

void StreamWatchdog::Run() {
  // A few looks per timeout: a stream ends between 1 and 1.25 timeouts after its last message.
  const auto period = std::max(std::chrono::milliseconds(10), idle_timeout_ / 4);
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_.wait_for(lock, period, [this] { return stopping_; })) {
    const Clock::rep now = Clock::now().time_since_epoch().count();
    const Clock::rep limit = std::chrono::duration_cast<Clock::duration>(idle_timeout_).count();
    for (const std::shared_ptr<Entry>& entry : entries_) {
      if (entry->ended || now - entry->last_touch.load(std::memory_order_relaxed) <= limit) {
        continue;
      }
      entry->ended = true;
      entry->context->TryCancel();
      LogLine(absl::StrCat("ended an idle stream from ", entry->peer));
    }
  }
}

}  // namespace motiondb::server
