// The rules a clip's name must keep, public so that a cluster's router refuses a bad name before
// it reserves it cluster-wide (the Database checks it again on every write).
#ifndef MOTIONDB_STORAGE_CLIP_NAME_CHECK_H_
#define MOTIONDB_STORAGE_CLIP_NAME_CHECK_H_

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace motiondb::storage {

// Text util/name_text.h accepts, 1 to kMaxNameBytes bytes (storage/record_limits.h), and a
// relative path: '/' separates segments (studios name takes "session1/take_001"), none of which
// may be empty, "." or "..", so no leading, trailing or doubled '/'. A clip name then maps to a
// path under an export folder that cannot leave it, and one clip has one spelling ("a//b" and
// "a/./b" are not a second "a/b"). INVALID_ARGUMENT naming the clip name otherwise.
absl::Status CheckClipName(absl::string_view name);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_CLIP_NAME_CHECK_H_
