// What a node says of itself under its key /CLUSTER/nodes/NODE_ID while it lives.
#ifndef MOTIONDB_CLUSTER_NODE_INFO_H_
#define MOTIONDB_CLUSTER_NODE_INFO_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace motiondb::cluster {

class EtcdClient;

struct NodeInfo {
  std::string node_id;
  // Where its gRPC face answers (host:port).
  std::string address;
  // "shard" (holds logical shards) or "router" (serves the public API over the shards).
  std::string role;
  // The logical shards the map gives it, as it last saw the map.
  std::vector<int> shards;
  // The lease its key lives under (read from etcd, not part of the value).
  int64_t lease = 0;

  // {"address":...,"role":...,"shards":[...]} (node_id and lease are the key's).
  std::string ToJson() const;
  static absl::StatusOr<NodeInfo> FromJson(const std::string& node_id, const std::string& text);
};

// The roles a node may have.
inline bool IsNodeRole(const std::string& role) { return role == "shard" || role == "router"; }

// Every live node of `cluster`, by id.
absl::StatusOr<std::vector<NodeInfo>> ListNodes(const EtcdClient& etcd, const std::string& cluster);

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_NODE_INFO_H_
