// A stored clip's frames read through blob handles, only the bytes of the range asked for: what
// GetClip reads, and the operators' and poses' ranges of a long take.
//
// Not thread-safe: uses the connection it is given (storage/sqlite_connection.h).
#ifndef MOTIONDB_STORAGE_INTERNAL_CLIP_FRAMES_H_
#define MOTIONDB_STORAGE_INTERNAL_CLIP_FRAMES_H_

#include <cstdint>
#include <optional>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "storage/database.h"
#include "storage/sqlite_connection.h"

namespace motiondb::storage {

// The clip's record and its frames `frames` (all of them when unset). NOT_FOUND for an unknown
// clip; OUT_OF_RANGE when `frames` is empty or not inside it; DATA_LOSS when the stored bytes
// do not decode.
absl::StatusOr<StoredClip> ReadStoredClip(SqliteConnection& db, int64_t clip_id,
                                          std::optional<FrameRange> frames);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_INTERNAL_CLIP_FRAMES_H_
