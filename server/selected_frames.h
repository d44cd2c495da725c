// The frames a request selects of a stored clip, read from the database without the others: an
// export, an edit or a clip's poses of a 10 s range of a long take decode 10 s.
#ifndef MOTIONDB_SERVER_SELECTED_FRAMES_H_
#define MOTIONDB_SERVER_SELECTED_FRAMES_H_

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"
#include "server/frame_conversion.h"
#include "storage/database.h"

namespace motiondb::server {

struct SelectedFrames {
  storage::ClipRecord record;  // of the whole clip
  FrameRange frames;           // at the clip's rate
  Clip clip;                   // those frames only
};

// NOT_FOUND for an unknown clip; INVALID_ARGUMENT naming `field` for a range outside it.
absl::StatusOr<SelectedFrames> ReadSelectedFrames(storage::Database& database,
                                                  const ClipSelection& selection,
                                                  absl::string_view field);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SELECTED_FRAMES_H_
