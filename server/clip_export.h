// Exporting a stored clip, or a range of it, as a BVH file: whole in one answer
// (ClipService.ExportClip), within the server's answer limit, or written piece by piece as its
// frames are read (ExportClipStream), whatever its size.
#ifndef MOTIONDB_SERVER_CLIP_EXPORT_H_
#define MOTIONDB_SERVER_CLIP_EXPORT_H_

#include <functional>
#include <string>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "server/answer_limit.h"
#include "server/frame_conversion.h"
#include "storage/database.h"

namespace motiondb::server {

// The threads that write one BVH answer, an export's or an edit's (WriteBvh, Resample): every
// core, so that one caller's 10 s at 120 fps (1200 frames) is not bound to one; calls under way
// at once share the cores.
inline constexpr int kBvhAnswerThreads = 0;

// A streamed export's pieces hold the rows of at most this many bytes of text (the first piece,
// the header, may be longer): about 1 MiB, far below any message limit, large enough that a
// message's costs vanish.
inline constexpr int64_t kExportPieceBytes = int64_t{1} << 20;

struct ExportedBvh {
  // Suggested: "<name>.bvh", or "<name>_<first>-<last>.bvh" for a range, with each '/' (or
  // backslash) in the name as '_': "session1/take_001" suggests "session1_take_001.bvh".
  std::string file_name;
  std::string bvh;
  FrameRange frames;  // at the clip's rate
};

// NOT_FOUND for an unknown clip; INVALID_ARGUMENT naming "clip" for a range outside it;
// RESOURCE_EXHAUSTED, before the frames are read, when the text could exceed `answers` (the
// error names the streamed export); CANCELLED once `should_stop` says so. The text is
// StreamClipExport's pieces joined.
absl::StatusOr<ExportedBvh> ExportClip(storage::Database& database, const ClipSelection& selection,
                                       const AnswerLimit& answers,
                                       const std::function<bool()>& should_stop);

// The text ExportClip makes, of any length, handed to `emit` in pieces as the frames are read in
// batches (storage::Database::ReadClipFrames): memory holds a piece whatever the clip's size.
// The first piece carries file_name and frames, and the header; each other piece (file name
// empty) the rows of frames, at most kExportPieceBytes long. `emit`'s first error (a client gone)
// ends the export and is returned; `should_stop` is asked before each piece (CANCELLED). Errors
// before the first piece as ExportClip's.
absl::Status StreamClipExport(storage::Database& database, const ClipSelection& selection,
                              const std::function<absl::Status(ExportedBvh piece)>& emit,
                              const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CLIP_EXPORT_H_
