#include "cluster/shard_map_store.h"

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"
#include "cluster/node_info.h"
#include "util/status_macros.h"

namespace motiondb::cluster {

ShardMapStore::ShardMapStore(const EtcdClient& etcd, std::string cluster)
    : etcd_(etcd), cluster_(std::move(cluster)) {}

absl::StatusOr<StoredShardMap> ShardMapStore::Read(absl::Time deadline) const {
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<KeyValue> kv,
                            etcd_.Get(ShardMapKey(cluster_), deadline));
  if (!kv) {
    return absl::NotFoundError(
        absl::StrCat("cluster '", cluster_, "' is not initialised (motiondb cluster init)"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(ShardMap map, ShardMap::FromJson(kv->value));
  return StoredShardMap{.map = std::move(map), .revision = kv->mod_revision};
}

absl::StatusOr<StoredShardMap> ShardMapStore::Create(
    int shard_count, const std::vector<std::string>& node_ids) const {
  if (shard_count < 1 || shard_count > kMaxShardCount) {
    return absl::InvalidArgumentError(
        absl::StrCat("a cluster has 1 to ", kMaxShardCount, " shards, not ", shard_count));
  }
  if (node_ids.empty()) {
    return absl::InvalidArgumentError("no shard node to give the shards to");
  }
  ShardMap map{.epoch = 1, .owners = {}};
  for (int shard = 0; shard < shard_count; ++shard) {
    map.owners.push_back(node_ids[shard % node_ids.size()]);
  }
  MOTIONDB_ASSIGN_OR_RETURN(const SwapOutcome outcome,
                            etcd_.CompareAndSwap(ShardMapKey(cluster_), 0, map.ToJson()));
  if (!outcome.written) {
    return absl::AlreadyExistsError(
        absl::StrCat("cluster '", cluster_, "' is initialised already (motiondb cluster status)"));
  }
  return StoredShardMap{.map = std::move(map), .revision = outcome.revision};
}

absl::StatusOr<StoredShardMap> ShardMapStore::Replace(const StoredShardMap& read,
                                                      const ShardMap& next) const {
  if (next.epoch != read.map.epoch + 1 || next.shard_count() != read.map.shard_count()) {
    return absl::InvalidArgumentError(
        absl::StrCat("a new shard map has the epoch after the old one's (", read.map.epoch + 1,
                     ", not ", next.epoch, ") and its shard count (", read.map.shard_count(), ")"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const SwapOutcome outcome,
      etcd_.CompareAndSwap(ShardMapKey(cluster_), read.revision, next.ToJson()));
  if (!outcome.written) {
    const absl::StatusOr<ShardMap> now = outcome.current
                                             ? ShardMap::FromJson(outcome.current->value)
                                             : absl::NotFoundError("the shard map is gone");
    return absl::AbortedError(absl::StrCat(
        "the shard map changed since it was read at epoch ", read.map.epoch,
        now.ok() ? absl::StrCat(" (epoch ", now->epoch, " now)") : "; nothing written"));
  }
  return StoredShardMap{.map = next, .revision = outcome.revision};
}

absl::StatusOr<StoredShardMap> ShardMapStore::MoveShard(int shard,
                                                        const std::string& node_id) const {
  MOTIONDB_ASSIGN_OR_RETURN(const StoredShardMap read, Read());
  if (shard < 0 || shard >= read.map.shard_count()) {
    return absl::InvalidArgumentError(absl::StrCat("shard ", shard, " is out of range: cluster '",
                                                   cluster_, "' has shards 0 to ",
                                                   read.map.shard_count() - 1));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<KeyValue> node,
                            etcd_.Get(NodeKey(cluster_, node_id)));
  if (!node) {
    return absl::NotFoundError(absl::StrCat("node '", node_id, "' is not a live node of cluster '",
                                            cluster_, "' (motiondb cluster status lists them)"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const NodeInfo info, NodeInfo::FromJson(node_id, node->value));
  if (info.role != "shard") {
    return absl::FailedPreconditionError(
        absl::StrCat("node '", node_id, "' is a ", info.role, ", not a shard node"));
  }
  if (read.map.owners[shard] == node_id) {
    return absl::FailedPreconditionError(
        absl::StrCat("shard ", shard, " is on node '", node_id, "' already"));
  }
  ShardMap next = read.map;
  next.epoch += 1;
  next.owners[shard] = node_id;
  return Replace(read, next);
}

}  // namespace motiondb::cluster
