// A clip's content hash: SHA-256, in lower-case hex, of what storage keeps of its motion (the
// frame time as float32, the joint layout blob, the rotation and the position blobs;
// storage/blob_codec.h). Two uploads hash the same exactly when they store the same motion, so
// files that differ only in whitespace, number formatting or digits beyond float32 hash the
// same, while a different frame rate, skeleton or frame does not.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_STORAGE_CONTENT_HASH_H_
#define MOTIONDB_STORAGE_CONTENT_HASH_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"

namespace motiondb::storage {

// The hash of `clip` as InsertClip would store it. INTERNAL only when OpenSSL fails.
absl::StatusOr<std::string> ContentHash(const Clip& clip);

// The hash of a stored clip's columns (what InsertClip and the schema's backfill use).
absl::StatusOr<std::string> ContentHashOfBlobs(double frame_time, absl::string_view layout,
                                               absl::string_view rotations,
                                               absl::string_view positions);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_CONTENT_HASH_H_
