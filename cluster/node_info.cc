#include "cluster/node_info.h"

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"
#include "cluster/etcd_client.h"

namespace motiondb::cluster {

std::string NodeInfo::ToJson() const {
  return nlohmann::json{{"address", address}, {"role", role}, {"shards", shards}}.dump();
}

absl::StatusOr<NodeInfo> NodeInfo::FromJson(const std::string& node_id, const std::string& text) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!json.is_object() || !json.contains("address") || !json["address"].is_string() ||
      !json.contains("role") || !json["role"].is_string() || !json.contains("shards") ||
      !json["shards"].is_array()) {
    return absl::InvalidArgumentError(
        absl::StrCat("node ", node_id, ": not a node's value: ", text.substr(0, 80)));
  }
  NodeInfo node{.node_id = node_id,
                .address = json["address"].get<std::string>(),
                .role = json["role"].get<std::string>(),
                .shards = {},
                .lease = 0};
  for (const nlohmann::json& shard : json["shards"]) {
    if (!shard.is_number_integer()) {
      return absl::InvalidArgumentError(absl::StrCat("node ", node_id, ": a shard not a number"));
    }
    node.shards.push_back(shard.get<int>());
  }
  return node;
}

absl::StatusOr<std::vector<NodeInfo>> ListNodes(const EtcdClient& etcd,
                                                const std::string& cluster) {
  const std::string prefix = NodesPrefix(cluster);
  absl::StatusOr<std::vector<KeyValue>> kvs = etcd.Range(prefix);
  if (!kvs.ok()) return kvs.status();
  std::vector<NodeInfo> nodes;
  for (const KeyValue& kv : *kvs) {
    absl::StatusOr<NodeInfo> node = NodeInfo::FromJson(kv.key.substr(prefix.size()), kv.value);
    if (!node.ok()) return node.status();
    node->lease = kv.lease;
    nodes.push_back(*std::move(node));
  }
  return nodes;
}

}  // namespace motiondb::cluster
