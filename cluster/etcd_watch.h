// A watch on every key under a prefix, kept up on a thread of its own: when its stream breaks
// (a member down, no leader) it opens another, on the next member, from the revision after the
// last one it delivered, so nothing is missed or delivered twice; when that revision has been
// compacted away it says so (`resync`) and goes on from the present. Thread-safe; callbacks run
// on the watch's thread, one at a time.
#ifndef MOTIONDB_CLUSTER_ETCD_WATCH_H_
#define MOTIONDB_CLUSTER_ETCD_WATCH_H_

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace grpc {
class ClientContext;
}

namespace motiondb::cluster {

class EtcdChannels;
struct KeyValue;

struct WatchEvent {
  bool deleted = false;  // else a put
  // The key after the write (a deletion: its key and mod_revision only).
  std::shared_ptr<const KeyValue> kv;
};

class EtcdWatch {
 public:
  struct Callbacks {
    // The events of one revision or more, in revision order.
    std::function<void(const std::vector<WatchEvent>&)> events;
    // Events may have been missed (compacted away while no stream was open): read afresh.
    std::function<void()> resync;
    // Whether a stream is open (false while every member is unreachable).
    std::function<void(bool connected)> connected;
  };

  // Starts watching from `start_revision` (0: from now). Use EtcdClient::Watch.
  EtcdWatch(std::shared_ptr<const EtcdChannels> channels, std::string prefix,
            int64_t start_revision, Callbacks callbacks);
  // Cancels the stream and waits for the thread; no callback runs after it returns.
  ~EtcdWatch();
  EtcdWatch(const EtcdWatch&) = delete;
  EtcdWatch& operator=(const EtcdWatch&) = delete;

 private:
  void Run();
  // One stream on `member` until it ends; false when it could not be opened.
  bool Stream(size_t member);

  const std::shared_ptr<const EtcdChannels> channels_;
  const std::string prefix_;
  const Callbacks callbacks_;
  int64_t next_revision_;  // the watch thread's alone

  std::mutex mutex_;
  std::condition_variable stopped_;
  bool stopping_ = false;                   // guarded by mutex_
  grpc::ClientContext* context_ = nullptr;  // the open stream's, guarded by mutex_
  std::thread thread_;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_ETCD_WATCH_H_
