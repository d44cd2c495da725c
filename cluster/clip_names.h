// Cluster-wide unique clip names: a router reserves a clip's name in etcd
// (/CLUSTER/clip_names/NAME, holding the clip's id) before the clip is stored on its shard, so
// that no two shards store the same name. A key is created only when absent and deleted only by
// a transaction on the revision that held the clip's id, so a name has one holder at a time.
// Thread-safe (no state of its own).
#ifndef MOTIONDB_CLUSTER_CLIP_NAMES_H_
#define MOTIONDB_CLUSTER_CLIP_NAMES_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "cluster/etcd_client.h"

namespace motiondb::cluster {

class ClipNames {
 public:
  // `etcd` must outlive the names. `max_name_bytes` is storage's limit on a clip name
  // (storage::kMaxNameBytes), given by the caller since this layer may not use storage; it is
  // all that is checked here of a name (the full rule is storage's), bounding the key.
  ClipNames(const EtcdClient& etcd, std::string cluster, size_t max_name_bytes);

  // Reserves `name` for clip `clip_id`: OK when it was free or is held by that clip already (a
  // retried request). ALREADY_EXISTS "clip name 'NAME' is taken by clip N" when another clip
  // holds it; INVALID_ARGUMENT for an empty or too long name or an id below 1.
  absl::Status Reserve(const std::string& name, int64_t clip_id) const;
  // Frees `name` if clip `clip_id` holds it: whether it did. A name free or held by another clip
  // is left as it is (false).
  absl::StatusOr<bool> Release(const std::string& name, int64_t clip_id) const;
  // Moves `name` from clip `from` to clip `to` (a replacement stored under a new id), only if
  // `from` holds it: whether it did. A name free or held by another clip is left as it is.
  // INVALID_ARGUMENT for a bad name or an id below 1.
  absl::StatusOr<bool> Reassign(const std::string& name, int64_t from, int64_t to) const;
  // The clip holding `name`, or nullopt when it is free.
  absl::StatusOr<std::optional<int64_t>> Lookup(const std::string& name) const;

 private:
  absl::Status CheckName(const std::string& name) const;
  // Runs `change` on the name's key at its revision while clip `clip_id` holds it, again when
  // the key changed meanwhile (up to a few times: ABORTED naming `what` then): whether it took.
  absl::StatusOr<bool> ChangeIfHeld(
      const std::string& name, int64_t clip_id, absl::string_view what,
      const std::function<absl::StatusOr<bool>(const std::string& key, int64_t revision)>& change)
      const;

  const EtcdClient& etcd_;
  const std::string cluster_;
  const size_t max_name_bytes_;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLIP_NAMES_H_
