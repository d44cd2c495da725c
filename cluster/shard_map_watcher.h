// The last shard map a node has seen, kept current by a watch on its key, and read without
// waiting: readers copy a shared_ptr under a short lock (read-copy-update, as
// server/index_registry.h holds the indices). A map replaces the one held only when its epoch
// is higher, so a stale read never undoes a newer map; while etcd is unreachable the last map
// stays, for reads (a search may use a map that is a little old: a moved shard's old node still
// holds its copy until told otherwise). A write must not: it waits for a map confirmed by a live
// watch (CurrentMap). Thread-safe.
#ifndef MOTIONDB_CLUSTER_SHARD_MAP_WATCHER_H_
#define MOTIONDB_CLUSTER_SHARD_MAP_WATCHER_H_

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/cluster_options.h"
#include "cluster/etcd_client.h"
#include "cluster/shard_map.h"
#include "cluster/shard_map_store.h"

namespace motiondb::cluster {

class ShardMapWatcher {
 public:
  // Starts watching `options.cluster`'s map; `on_change` runs on the watch's thread with each
  // newer map. `etcd` must outlive the watcher.
  ShardMapWatcher(const EtcdClient& etcd, const ClusterOptions& options,
                  std::function<void(const ShardMap&)> on_change);
  ~ShardMapWatcher();

  // The newest map seen; nullptr before the first (the cluster not initialised yet, or etcd
  // unreachable since the start).
  std::shared_ptr<const ShardMap> map() const;
  // The newest map, known to be current: held since the watch stream opened and still open (its
  // member has a leader: a member cut off from the others ends it), or else read from etcd now
  // (a linearizable read), again until `deadline`, then UNAVAILABLE naming the last epoch seen;
  // NOT_FOUND when the cluster has no map. What a write needs, so that it never goes to a
  // shard's old node after a move it could not hear of.
  absl::StatusOr<std::shared_ptr<const ShardMap>> CurrentMap(absl::Time deadline) const;

 private:
  // Reads the map afresh (on every new stream: what changed while none was open).
  void Refresh();
  void Offer(const ShardMap& map);
  void SetCurrent(bool current);

  const ShardMapStore store_;
  const ClusterOptions options_;
  const std::function<void(const ShardMap&)> on_change_;
  mutable std::mutex mutex_;
  mutable std::condition_variable current_changed_;
  std::shared_ptr<const ShardMap> map_;  // guarded by mutex_
  bool current_ = false;                 // guarded by mutex_: map_ is confirmed by a live watch
  std::unique_ptr<EtcdWatch> watch_;     // last: stopped first
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_SHARD_MAP_WATCHER_H_
