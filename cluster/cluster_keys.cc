#include "cluster/cluster_keys.h"

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"

namespace motiondb::cluster {

std::string NodesPrefix(const std::string& cluster) {
  return absl::StrCat("/", cluster, "/nodes/");
}

std::string NodeKey(const std::string& cluster, const std::string& node_id) {
  return NodesPrefix(cluster) + node_id;
}

std::string ShardMapKey(const std::string& cluster) {
  return absl::StrCat("/", cluster, "/shard_map");
}

absl::Status CheckClusterName(const std::string& name, const std::string& what) {
  bool valid = !name.empty() && name.size() <= 64;
  for (const char c : name) {
    valid = valid && (absl::ascii_isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' ||
                      c == '-');
  }
  if (valid) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(what, " '", name, "': want 1-64 letters, digits, '.', '_' or '-'"));
}

}  // namespace motiondb::cluster
