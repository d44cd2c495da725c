#include "server/selected_frames.h"

#include <utility>

#include "util/status_macros.h"

namespace motiondb::server {

absl::StatusOr<SelectedFrames> ReadSelectedFrames(storage::Database& database,
                                                  const ClipSelection& selection,
                                                  absl::string_view field) {
  // The record first, for the frame count the selection's open ends stand for; a clip's frames
  // never change once stored, so the second read agrees with it.
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord record,
                            database.GetClipRecord(selection.clip_id));
  MOTIONDB_ASSIGN_OR_RETURN(
      const FrameRange frames,
      ResolveFrameRange(selection, static_cast<int>(record.frame_count), field));
  MOTIONDB_ASSIGN_OR_RETURN(storage::StoredClip stored,
                            database.GetClip(selection.clip_id, frames));
  return SelectedFrames{std::move(stored.record), frames, std::move(stored.clip)};
}

}  // namespace motiondb::server
