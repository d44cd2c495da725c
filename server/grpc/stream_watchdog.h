// Ends client streams that have gone quiet or crawl. A synchronous handler blocked in Read()
// holds its server thread for as long as its client keeps the stream open without sending: 300
// idle IngestClipStream calls made 311 threads, and 32 streams sending a byte every 20 s kept
// every ingest out. One thread looks at the watched calls a few times a second and ends those
// idle for longer than the idle timeout, or slower on average than the least rate once its grace
// has passed, with DEADLINE_EXCEEDED and the reason; their Read() then fails, and the handler
// asks its Watch whether the watchdog is why.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_GRPC_STREAM_WATCHDOG_H_
#define MOTIONDB_SERVER_GRPC_STREAM_WATCHDOG_H_

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <grpcpp/server_context.h>

#include "absl/status/status.h"

namespace motiondb::server {

struct StreamLimits {
  // A stream that sends nothing for this long is ended; zero: never (--stream-idle-timeout-s).
  std::chrono::milliseconds idle_timeout{30'000};
  // A stream slower on average than this, once `rate_grace` has passed since it started, is
  // ended; zero: never (--min-upload-kbps).
  double min_bytes_per_s = 0;
  std::chrono::milliseconds rate_grace{10'000};
};

class StreamWatchdog {
 public:
  // With neither limit set, streams are never ended (and no thread runs).
  explicit StreamWatchdog(const StreamLimits& limits);
  ~StreamWatchdog();
  StreamWatchdog(const StreamWatchdog&) = delete;
  StreamWatchdog& operator=(const StreamWatchdog&) = delete;

  struct Entry;
  // One call watched from Watch() until it is destroyed, which must be before the call ends.
  class Watch {
   public:
    Watch(Watch&& other) noexcept;
    Watch& operator=(Watch&&) = delete;
    ~Watch();
    // `bytes` arrived: the idle time starts again.
    void Touch(size_t bytes);
    // DEADLINE_EXCEEDED saying which limit the stream broke once the watchdog ended it; OK
    // otherwise.
    absl::Status Status() const;

   private:
    friend class StreamWatchdog;
    Watch(StreamWatchdog* watchdog, std::shared_ptr<Entry> entry)
        : watchdog_(watchdog), entry_(std::move(entry)) {}

    StreamWatchdog* watchdog_;  // null once moved from
    std::shared_ptr<Entry> entry_;
  };

  Watch Start(grpc::ServerContext* context);

 private:
  void Run();

  const StreamLimits limits_;
  std::mutex mutex_;
  std::condition_variable stop_;
  bool stopping_ = false;                        // guarded by mutex_
  std::vector<std::shared_ptr<Entry>> entries_;  // guarded by mutex_
  std::thread thread_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_STREAM_WATCHDOG_H_
