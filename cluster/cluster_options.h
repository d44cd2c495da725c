// What a node of a cluster is told (motiondb-server --cluster ...).
#ifndef MOTIONDB_CLUSTER_CLUSTER_OPTIONS_H_
#define MOTIONDB_CLUSTER_CLUSTER_OPTIONS_H_

#include <functional>
#include <string>

#include "absl/time/time.h"
#include "cluster/etcd_options.h"
#include "cluster/node_info.h"

namespace motiondb::cluster {

struct ClusterOptions {
  // The etcd members (--cluster).
  EtcdOptions etcd;
  // The cluster's name, the first element of its keys (--cluster-name).
  std::string cluster = "motiondb";
  // This node: its id (--node-id), gRPC address and role (--role); its shards come from the map.
  NodeInfo node{.node_id = "", .address = "", .role = "shard", .shards = {}, .lease = 0};
  // How long a node that stopped renewing stays listed: a dead node disappears within it
  // (--cluster-lease-s). Renewed every third of it.
  absl::Duration lease_ttl = absl::Seconds(5);
  // The longest clip name (storage::kMaxNameBytes, given by the server: this layer may not use
  // storage); a router bounds the names it reserves by it.
  size_t max_clip_name_bytes = 0;
  // Where changes of state go (registered, lost, the map's new epoch); none by default.
  std::function<void(const std::string& line)> log;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLUSTER_OPTIONS_H_
