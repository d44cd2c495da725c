// The last shard map a node has seen, kept current by a watch on its key, and read without
// waiting: readers copy a shared_ptr under a short lock (read-copy-update, as
// server/index_registry.h holds the indices). A map replaces the one held only when its epoch
// is higher, so a stale read never undoes a newer map; while etcd is unreachable the last map
// stays. That serves reads (a search from a map a little old finds a moved shard's data still on
// its old node); a write asks etcd (CurrentMap). Thread-safe.
#ifndef MOTIONDB_CLUSTER_SHARD_MAP_WATCHER_H_
#define MOTIONDB_CLUSTER_SHARD_MAP_WATCHER_H_

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
  // The map as etcd holds it now (a linearizable read, one etcd call while etcd answers: a write
  // costs far more), tried again while etcd is unreachable until `deadline`, then UNAVAILABLE
  // naming the last epoch seen; NOT_FOUND when the cluster has no map. What a write needs rather
  // than map(): the watch may lag (a member cut off from the others keeps its streams open for
  // a while). A move can still land between the read and the write; the shard's own check of
  // the map it holds is what refuses such a write.
  absl::StatusOr<ShardMap> CurrentMap(absl::Time deadline) const;

 private:
  // Reads the map afresh (on every new stream: what changed while none was open).
  void Refresh();
  void Offer(const ShardMap& map);

  const ShardMapStore store_;
  const ClusterOptions options_;
  const std::function<void(const ShardMap&)> on_change_;
  mutable std::mutex mutex_;
  std::shared_ptr<const ShardMap> map_;  // guarded by mutex_
  std::unique_ptr<EtcdWatch> watch_;     // last: stopped first
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_SHARD_MAP_WATCHER_H_
