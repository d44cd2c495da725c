// The HTTP face's worker threads and the line of requests waiting for one: bounded, so that a
// burst is refused at once (503) rather than queued for ever behind slow work. A request reaches
// the line only once it has arrived whole (server/http/connection_loop.h): a worker never waits
// for a client to send.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_HTTP_WORKER_POOL_H_
#define MOTIONDB_SERVER_HTTP_WORKER_POOL_H_

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace motiondb::server {

class WorkerPool {
 public:
  WorkerPool(int threads, int max_waiting);
  ~WorkerPool();  // Join()
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Queues `task`; false when `max_waiting` tasks wait already (or the pool is joining).
  bool TryPost(std::function<void()> task);
  // Runs what is queued, then ends the threads.
  void Join();

  int busy() const;
  int waiting() const;

 private:
  void Work();

  const int max_waiting_;
  mutable std::mutex mutex_;
  std::condition_variable posted_;
  std::deque<std::function<void()>> tasks_;  // guarded by mutex_
  int busy_ = 0;                             // guarded by mutex_
  bool joining_ = false;                     // guarded by mutex_
  std::vector<std::thread> threads_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_WORKER_POOL_H_
