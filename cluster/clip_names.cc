#include "cluster/clip_names.h"

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"
#include "util/name_text.h"
#include "util/status_macros.h"

namespace motiondb::cluster {
namespace {

// A failed delete means the key was deleted since it was read (a release racing this one), and
// perhaps reserved again: a few attempts settle it.
constexpr int kMaxChangeAttempts = 5;

}  // namespace

ClipNames::ClipNames(const EtcdClient& etcd, std::string cluster, size_t max_name_bytes)
    : etcd_(etcd), cluster_(std::move(cluster)), max_name_bytes_(max_name_bytes) {}

absl::Status ClipNames::CheckName(const std::string& name) const {
  if (name.empty()) return absl::InvalidArgumentError("a clip name is empty");
  if (name.size() > max_name_bytes_) {
    return absl::InvalidArgumentError(absl::StrCat("clip name ", QuotedNameText(name), " is ",
                                                   name.size(), " bytes long, at most ",
                                                   max_name_bytes_, " are allowed"));
  }
  return absl::OkStatus();
}

absl::Status ClipNames::Reserve(const std::string& name, int64_t clip_id) const {
  MOTIONDB_RETURN_IF_ERROR(CheckName(name));
  if (clip_id < 1) return absl::InvalidArgumentError(absl::StrCat("clip id ", clip_id));
  const std::string key = ClipNameKey(cluster_, name);
  MOTIONDB_ASSIGN_OR_RETURN(const SwapOutcome outcome,
                            etcd_.CompareAndSwap(key, 0, absl::StrCat(clip_id)));
  if (outcome.written) return absl::OkStatus();
  if (!outcome.current) {  // etcd's refusal carries the key, read in the same transaction
    return absl::InternalError(absl::StrCat("etcd refused to create ", QuotedNameText(key),
                                            " and did not answer with what it holds"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t holder, PositiveDecimalOf(key, outcome.current->value));
  if (holder == clip_id) return absl::OkStatus();
  return absl::AlreadyExistsError(
      absl::StrCat("clip name ", QuotedNameText(name), " is taken by clip ", holder));
}

absl::StatusOr<bool> ClipNames::ChangeIfHeld(
    const std::string& name, int64_t clip_id, absl::string_view what,
    const std::function<absl::StatusOr<bool>(const std::string& key, int64_t revision)>& change)
    const {
  MOTIONDB_RETURN_IF_ERROR(CheckName(name));
  const std::string key = ClipNameKey(cluster_, name);
  for (int attempt = 0; attempt < kMaxChangeAttempts; ++attempt) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::optional<KeyValue> kv, etcd_.Get(key));
    if (!kv) return false;
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t holder, PositiveDecimalOf(key, kv->value));
    if (holder != clip_id) return false;
    MOTIONDB_ASSIGN_OR_RETURN(const bool changed, change(key, kv->mod_revision));
    if (changed) return true;
  }
  return absl::AbortedError(absl::StrCat("clip name ", QuotedNameText(name),
                                         " changed under each of ", kMaxChangeAttempts,
                                         " attempts to ", what, " it"));
}

absl::StatusOr<bool> ClipNames::Release(const std::string& name, int64_t clip_id) const {
  return ChangeIfHeld(name, clip_id, "release", [&](const std::string& key, int64_t revision) {
    return etcd_.DeleteIfRevision(key, revision);
  });
}

absl::StatusOr<bool> ClipNames::Reassign(const std::string& name, int64_t from, int64_t to) const {
  if (to < 1) return absl::InvalidArgumentError(absl::StrCat("clip id ", to));
  return ChangeIfHeld(name, from, "reassign",
                      [&](const std::string& key, int64_t revision) -> absl::StatusOr<bool> {
                        MOTIONDB_ASSIGN_OR_RETURN(
                            const SwapOutcome outcome,
                            etcd_.CompareAndSwap(key, revision, absl::StrCat(to)));
                        return outcome.written;
                      });
}

absl::StatusOr<std::optional<int64_t>> ClipNames::Lookup(const std::string& name) const {
  MOTIONDB_RETURN_IF_ERROR(CheckName(name));
  const std::string key = ClipNameKey(cluster_, name);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<KeyValue> kv, etcd_.Get(key));
  if (!kv) return std::nullopt;
  return PositiveDecimalOf(key, kv->value);
}

}  // namespace motiondb::cluster
