#include "server/space_lookup.h"

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb::server {

absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> FindSpace(const IndexRegistry& registry,
                                                               const std::string& name) {
  if (name.empty()) return absl::InvalidArgumentError("space: a space name is required");
  std::shared_ptr<const SpaceSnapshot> snapshot = registry.Find(name);
  if (snapshot == nullptr) return absl::NotFoundError(absl::StrCat("no space named '", name, "'"));
  return snapshot;
}

absl::Status CheckClipInSpace(storage::Database& database, const SpaceSnapshot& snapshot,
                              int64_t clip_id) {
  if (snapshot.clips.contains(clip_id)) return absl::OkStatus();
  absl::StatusOr<storage::ClipRecord> record = database.GetClipRecord(clip_id);
  if (absl::IsNotFound(record.status())) {
    return absl::NotFoundError(absl::StrCat("no clip with id ", clip_id));
  }
  MOTIONDB_RETURN_IF_ERROR(record.status());
  if (record->skeleton_id != snapshot.record.skeleton_id) {
    return absl::FailedPreconditionError(
        absl::StrCat("clip ", clip_id, " is on skeleton ", record->skeleton_id, " but space '",
                     snapshot.record.name, "' is on skeleton ", snapshot.record.skeleton_id));
  }
  return absl::UnavailableError(absl::StrCat("clip ", clip_id, " is being indexed in space '",
                                             snapshot.record.name, "'; retry"));
}

}  // namespace motiondb::server
