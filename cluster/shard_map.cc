#include "cluster/shard_map.h"

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"

namespace motiondb::cluster {

std::vector<int> ShardMap::ShardsOf(const std::string& node_id) const {
  std::vector<int> shards;
  for (int shard = 0; shard < shard_count(); ++shard) {
    if (owners[shard] == node_id) shards.push_back(shard);
  }
  return shards;
}

std::map<std::string, int> ShardMap::ShardsPerNode() const {
  std::map<std::string, int> counts;
  for (const std::string& owner : owners) ++counts[owner];
  return counts;
}

std::string ShardMap::ToJson() const {
  return nlohmann::json{{"epoch", epoch}, {"owners", owners}}.dump();
}

absl::StatusOr<ShardMap> ShardMap::FromJson(const std::string& text) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!json.is_object() || !json.contains("epoch") || !json["epoch"].is_number_integer() ||
      !json.contains("owners") || !json["owners"].is_array()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "not a shard map (want {\"epoch\":N,\"owners\":[...]}): ", text.substr(0, 80)));
  }
  ShardMap map{.epoch = json["epoch"].get<int64_t>(), .owners = {}};
  for (const nlohmann::json& owner : json["owners"]) {
    if (!owner.is_string())
      return absl::InvalidArgumentError("a shard map's owner is not a string");
    map.owners.push_back(owner.get<std::string>());
  }
  if (map.owners.empty() || map.shard_count() > kMaxShardCount || map.epoch < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("a shard map with ", map.shard_count(), " shards and epoch ", map.epoch));
  }
  return map;
}

int ShardOfClip(int64_t clip_id, int shard_count) {
  uint64_t x = static_cast<uint64_t>(clip_id);
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return static_cast<int>(x % static_cast<uint64_t>(shard_count));
}

}  // namespace motiondb::cluster
