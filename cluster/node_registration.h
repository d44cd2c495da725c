// A node's key, /CLUSTER/nodes/NODE_ID, kept alive under a lease by a thread of its own: it
// renews the lease every third of its TTL; when etcd is unreachable it keeps trying (the node
// goes on serving meanwhile), and when the lease has expired it takes a new one and writes the
// key again, unless another live node has taken the id meanwhile. Thread-safe.
#ifndef MOTIONDB_CLUSTER_NODE_REGISTRATION_H_
#define MOTIONDB_CLUSTER_NODE_REGISTRATION_H_

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "cluster/cluster_options.h"
#include "cluster/etcd_client.h"

namespace motiondb::cluster {

class LeaseKeeper;

class NodeRegistration {
 public:
  // Registers once before returning. ALREADY_EXISTS, naming the holder, when a live node holds
  // the id (nothing started); etcd unreachable is no error: the node then registers as soon as
  // etcd answers. `on_change` runs (on the registration's thread) whenever registered() changes.
  // `etcd` must outlive the registration.
  static absl::StatusOr<std::unique_ptr<NodeRegistration>> Start(
      const EtcdClient& etcd, const ClusterOptions& options,
      std::function<void(bool registered)> on_change);
  // Stops renewing and revokes the lease, so that the key goes at once rather than at expiry.
  ~NodeRegistration();
  NodeRegistration(const NodeRegistration&) = delete;
  NodeRegistration& operator=(const NodeRegistration&) = delete;

  // Whether the key is known to live: the last renewal or write succeeded.
  bool registered() const { return registered_.load(); }
  // The shards the node now holds, written to its key soon.
  void SetShards(std::vector<int> shards);

 private:
  NodeRegistration(const EtcdClient& etcd, const ClusterOptions& options,
                   std::function<void(bool)> on_change);
  // Renews the lease or, when needed, takes one and writes the key.
  absl::Status Step();
  absl::Status WriteKey(int64_t lease, const std::string& value);
  void Run();
  void Report(const absl::Status& status);

  const EtcdClient& etcd_;
  const ClusterOptions options_;
  const std::string key_;
  const std::function<void(bool)> on_change_;
  const std::unique_ptr<LeaseKeeper> lease_;  // the thread's (and Start's, before it runs)
  std::atomic<bool> registered_{false};
  std::string last_problem_;  // the thread's alone: a problem is logged when it changes

  std::mutex mutex_;
  std::condition_variable wake_;
  NodeInfo info_;          // guarded by mutex_
  bool dirty_ = true;      // guarded by mutex_: the key needs writing
  bool stopping_ = false;  // guarded by mutex_
  std::thread thread_;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_NODE_REGISTRATION_H_
