// The cluster's shard map: a fixed number of logical shards, set when the cluster is created,
// each held by one node, and an epoch that every change raises by one. A value: copy it, change
// the copy, and store it with ShardMapStore's compare-and-swap.
#ifndef MOTIONDB_CLUSTER_SHARD_MAP_H_
#define MOTIONDB_CLUSTER_SHARD_MAP_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace motiondb::cluster {

// Logical shards of a new cluster unless told otherwise (`motiondb cluster init --shards`).
inline constexpr int kDefaultShardCount = 64;
// Most logical shards a cluster may have: each is a SQLite file of its own.
inline constexpr int kMaxShardCount = 4096;

struct ShardMap {
  // 1 when created, +1 at every change.
  int64_t epoch = 0;
  // The node id holding each logical shard; its size is the cluster's shard count, for ever.
  std::vector<std::string> owners;

  int shard_count() const { return static_cast<int>(owners.size()); }
  // The shards `node_id` holds, ascending.
  std::vector<int> ShardsOf(const std::string& node_id) const;
  // Node id -> how many shards it holds.
  std::map<std::string, int> ShardsPerNode() const;

  // {"epoch":E,"owners":["node-a",...]}: the value of the map's etcd key.
  std::string ToJson() const;
  // INVALID_ARGUMENT, naming the problem, for text that is not such a map.
  static absl::StatusOr<ShardMap> FromJson(const std::string& text);
};

// The logical shard of the clip `clip_id` among `shard_count`: SplitMix64's finalizer of the
// id's 64 bits, modulo the count. Fixed for ever (it says where every stored clip lives): never
// std::hash, whose result is the library's to change.
int ShardOfClip(int64_t clip_id, int shard_count);

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_SHARD_MAP_H_
