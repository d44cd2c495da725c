// Exporting a stored clip, or a range of it, as a BVH file (ClipService.ExportClip).
#ifndef MOTIONDB_SERVER_CLIP_EXPORT_H_
#define MOTIONDB_SERVER_CLIP_EXPORT_H_

#include <string>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "server/frame_conversion.h"
#include "storage/database.h"

namespace motiondb::server {

// The threads that write one BVH answer, an export's or an edit's (WriteBvh, Resample): every
// core, so that one caller's 10 s at 120 fps (1200 frames) is not bound to one; calls under way
// at once share the cores.
inline constexpr int kBvhAnswerThreads = 0;

struct ExportedBvh {
  // Suggested: "<name>.bvh", or "<name>_<first>-<last>.bvh" for a range, with each '/' (or
  // backslash) in the name as '_': "session1/take_001" suggests "session1_take_001.bvh".
  std::string file_name;
  std::string bvh;
  FrameRange frames;  // at the clip's rate
};

// NOT_FOUND for an unknown clip; INVALID_ARGUMENT naming "clip" for a range outside it.
absl::StatusOr<ExportedBvh> ExportClip(storage::Database& database, const ClipSelection& selection);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CLIP_EXPORT_H_
