#include "server/clip_export.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/bvh/bvh_writer.h"
#include "server/selected_frames.h"
#include "util/status_macros.h"

namespace motiondb::server {

absl::StatusOr<ExportedBvh> ExportClip(storage::Database& database,
                                       const ClipSelection& selection) {
  MOTIONDB_ASSIGN_OR_RETURN(const SelectedFrames selected,
                            ReadSelectedFrames(database, selection, "clip"));
  ExportedBvh exported;
  exported.frames = selected.frames;
  MOTIONDB_ASSIGN_OR_RETURN(exported.bvh, WriteBvh(selected.clip, std::nullopt, kBvhAnswerThreads));
  const bool whole =
      exported.frames.first == 0 && exported.frames.last == selected.record.frame_count - 1;
  // A clip name's '/' separates folders ("session1/take_001"); the suggestion stays one file
  // name, which a client can write into any folder without making or leaving folders. A
  // backslash too, which separates folders on Windows.
  const std::string base = absl::StrReplaceAll(selected.record.name, {{"/", "_"}, {"\\", "_"}});
  exported.file_name =
      whole ? absl::StrCat(base, ".bvh")
            : absl::StrCat(base, "_", exported.frames.first, "-", exported.frames.last, ".bvh");
  return exported;
}

}  // namespace motiondb::server
