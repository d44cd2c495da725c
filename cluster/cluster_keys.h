// Where a cluster keeps its state in etcd (ARCHITECTURE.md, "The cluster in etcd"): every key
// under /CLUSTER/, so that clusters share an etcd without meeting.
#ifndef MOTIONDB_CLUSTER_CLUSTER_KEYS_H_
#define MOTIONDB_CLUSTER_CLUSTER_KEYS_H_

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace motiondb::cluster {

// /CLUSTER/nodes/: one key a live node, under its lease.
std::string NodesPrefix(const std::string& cluster);
// /CLUSTER/nodes/NODE_ID: {"address":...,"role":...,"shards":[...]} (NodeInfo).
std::string NodeKey(const std::string& cluster, const std::string& node_id);
// /CLUSTER/shard_map: the ShardMap's JSON.
std::string ShardMapKey(const std::string& cluster);
// /CLUSTER/next_clip_id: the first clip id no router has reserved, in decimal (ClipIdBlocks).
std::string NextClipIdKey(const std::string& cluster);
// /CLUSTER/clip_names/NAME: the id of the clip the name is reserved for, in decimal (ClipNames).
// NAME is the name's bytes unescaped: these keys are only read and written one at a time, never
// ranged over or watched by prefix, so a name holding '/' or beginning another has a key of its
// own all the same.
std::string ClipNameKey(const std::string& cluster, const std::string& name);
// /CLUSTER/elections/OFFICE: the node id of the office's leader, under its lease (LeaderElection).
std::string ElectionKey(const std::string& cluster, const std::string& office);
// The office every router campaigns for: its leader, the job coordinator, is to run the
// cluster's jobs (propagation), one at a time.
inline constexpr char kJobsOffice[] = "jobs";

// The positive decimal number (a clip id) that `key` holds as `value`; FAILED_PRECONDITION naming
// the key otherwise, since only motiondb writes these keys.
absl::StatusOr<int64_t> PositiveDecimalOf(const std::string& key, const std::string& value);

// A cluster name or node id: 1-64 letters, digits, '.', '_' or '-' (a key's path element).
// INVALID_ARGUMENT naming `what` ("--node-id") otherwise.
absl::Status CheckClusterName(const std::string& name, const std::string& what);

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLUSTER_KEYS_H_
