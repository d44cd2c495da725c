// Ends client streams that have gone quiet. A synchronous handler blocked in Read() holds its
// server thread (and, with --threads, a call slot) for as long as its client keeps the stream
// open without sending: 8 idle IngestClipStream calls locked a --threads 4 server out, and 300
// made 311 threads. One thread looks at the watched calls a few times per timeout and cancels
// (ServerContext::TryCancel) those idle for longer; their Read() then fails, and the handler
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

class StreamWatchdog {
 public:
  // `idle_timeout` zero: streams are never ended (and no thread runs).
  explicit StreamWatchdog(std::chrono::milliseconds idle_timeout);
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
    // Something arrived: the idle time starts again.
    void Touch();
    // DEADLINE_EXCEEDED saying how long the stream was idle once the watchdog ended it; OK
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

  const std::chrono::milliseconds idle_timeout_;
  std::mutex mutex_;
  std::condition_variable stop_;
  bool stopping_ = false;                        // guarded by mutex_
  std::vector<std::shared_ptr<Entry>> entries_;  // guarded by mutex_
  std::thread thread_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_STREAM_WATCHDOG_H_
