// The shard map in etcd (/CLUSTER/shard_map): created once, changed only by compare-and-swap on
// the revision it was read at, each change raising the epoch by one, so that of two changes
// made from the same map one fails instead of undoing the other. Thread-safe.
#ifndef MOTIONDB_CLUSTER_SHARD_MAP_STORE_H_
#define MOTIONDB_CLUSTER_SHARD_MAP_STORE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "cluster/etcd_client.h"
#include "cluster/shard_map.h"

namespace motiondb::cluster {

// A map as read from etcd, with the revision of its key's last write.
struct StoredShardMap {
  ShardMap map;
  int64_t revision = 0;
};

class ShardMapStore {
 public:
  // `etcd` must outlive the store.
  ShardMapStore(const EtcdClient& etcd, std::string cluster);

  // NOT_FOUND, saying to run `motiondb cluster init`, when the cluster has no map; by
  // `deadline` if that is sooner than the etcd call's timeout.
  absl::StatusOr<StoredShardMap> Read(absl::Time deadline = absl::InfiniteFuture()) const;
  // Creates the map at epoch 1: `shard_count` shards dealt in turn to `node_ids`.
  // ALREADY_EXISTS when the cluster has a map (nothing changed); INVALID_ARGUMENT for a count
  // out of 1..kMaxShardCount or no node.
  absl::StatusOr<StoredShardMap> Create(int shard_count,
                                        const std::vector<std::string>& node_ids) const;
  // Stores `next` when the map is still `read`; `next` must keep the shard count and have the
  // epoch after `read`'s. ABORTED, naming the epoch now, when the map changed since `read`.
  absl::StatusOr<StoredShardMap> Replace(const StoredShardMap& read, const ShardMap& next) const;
  // The map with `shard` held by `node_id` (a live shard node), by Replace. INVALID_ARGUMENT
  // for a shard out of range, NOT_FOUND for a node that is not live, FAILED_PRECONDITION for a
  // router or the node holding it already. Only the map changes: no data is copied.
  absl::StatusOr<StoredShardMap> MoveShard(int shard, const std::string& node_id) const;

 private:
  const EtcdClient& etcd_;
  const std::string cluster_;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_SHARD_MAP_STORE_H_
