// Finding a resident space and a clip in it, with the status a client should see when either is
// missing.
#ifndef MOTIONDB_SERVER_SPACE_LOOKUP_H_
#define MOTIONDB_SERVER_SPACE_LOOKUP_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

// NOT_FOUND when no space has that name.
absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> FindSpace(const IndexRegistry& registry,
                                                               const std::string& name);

// OK when the clip is indexed in the space. Otherwise NOT_FOUND when the clip does not exist,
// FAILED_PRECONDITION when it is of another skeleton, and UNAVAILABLE when it was stored after
// the snapshot was taken (a retry will find it).
absl::Status CheckClipInSpace(storage::Database& database, const SpaceSnapshot& snapshot,
                              int64_t clip_id);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SPACE_LOOKUP_H_
