#include "cluster/cluster_keys.h"

#include <charconv>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "util/name_text.h"

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

std::string NextClipIdKey(const std::string& cluster) {
  return absl::StrCat("/", cluster, "/next_clip_id");
}

std::string ClipNameKey(const std::string& cluster, const std::string& name) {
  return absl::StrCat("/", cluster, "/clip_names/", name);
}

std::string ElectionKey(const std::string& cluster, const std::string& office) {
  return absl::StrCat("/", cluster, "/elections/", office);
}

absl::StatusOr<int64_t> PositiveDecimalOf(const std::string& key, const std::string& value) {
  // std::from_chars, unlike absl::SimpleAtoi, takes neither '+' nor spaces; a '-' it takes is
  // refused below with every number under 1.
  int64_t number = 0;
  const char* end = value.data() + value.size();
  const std::from_chars_result parsed = std::from_chars(value.data(), end, number);
  if (parsed.ec == std::errc() && parsed.ptr == end && number > 0) return number;
  return absl::FailedPreconditionError(absl::StrCat("etcd key ", QuotedNameText(key), " holds ",
                                                    QuotedNameText(value),
                                                    ", not a positive decimal number"));
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
