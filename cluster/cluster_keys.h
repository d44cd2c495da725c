// Where a cluster keeps its state in etcd (ARCHITECTURE.md, "The cluster in etcd"): every key
// under /CLUSTER/, so that clusters share an etcd without meeting.
#ifndef MOTIONDB_CLUSTER_CLUSTER_KEYS_H_
#define MOTIONDB_CLUSTER_CLUSTER_KEYS_H_

#include <string>

#include "absl/status/status.h"

namespace motiondb::cluster {

// /CLUSTER/nodes/: one key a live node, under its lease.
std::string NodesPrefix(const std::string& cluster);
// /CLUSTER/nodes/NODE_ID: {"address":...,"role":...,"shards":[...]} (NodeInfo).
std::string NodeKey(const std::string& cluster, const std::string& node_id);
// /CLUSTER/shard_map: the ShardMap's JSON.
std::string ShardMapKey(const std::string& cluster);

// A cluster name or node id: 1-64 letters, digits, '.', '_' or '-' (a key's path element).
// INVALID_ARGUMENT naming `what` ("--node-id") otherwise.
absl::Status CheckClusterName(const std::string& name, const std::string& what);

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLUSTER_KEYS_H_
