// Exporting a stored clip, or a range of it (a search's hit), as a BVH or glTF file: whole in
// one answer (ClipService.ExportClip), within the server's answer limit, or in pieces
// (ExportClipStream): a BVH written as its frames are read, whatever its size; a glTF file,
// whose header counts every frame, made whole within the answer limit and sent in pieces.
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

enum class ExportFormat {
  kBvh,
  kGltf,  // a .gltf, its buffer embedded
  kGlb,   // a binary glTF
};

struct ExportedFile {
  // Suggested: "<name>.bvh" (.gltf, .glb), or "<name>_<first>-<last>.bvh" for a range, with
  // each '/' (or backslash) in the name as '_': "session1/take_001" suggests
  // "session1_take_001.bvh".
  std::string file_name;
  std::string bytes;
  FrameRange frames;  // at the clip's rate
};

// NOT_FOUND for an unknown clip; INVALID_ARGUMENT naming "clip" for a range outside it;
// RESOURCE_EXHAUSTED, before the frames are read, when the file could exceed `answers` (the
// error names the streamed export, for a BVH); CANCELLED once `should_stop` says so. The file
// is StreamClipExport's pieces joined.
absl::StatusOr<ExportedFile> ExportClip(storage::Database& database, const ClipSelection& selection,
                                        ExportFormat format, const AnswerLimit& answers,
                                        const std::function<bool()>& should_stop);

// The file ExportClip makes handed to `emit` in pieces of at most kExportPieceBytes. A BVH, of
// any length, as the frames are read in batches (storage::Database::ReadClipFrames): memory
// holds a piece whatever the clip's size; the first piece carries file_name and frames, and the
// header, each other piece (file name empty) the rows of frames. A glTF file is made whole
// first, within `answers`. `emit`'s first error (a client gone) ends the export and is
// returned; `should_stop` is asked before each piece (CANCELLED). Errors before the first piece
// as ExportClip's.
absl::Status StreamClipExport(storage::Database& database, const ClipSelection& selection,
                              ExportFormat format, const AnswerLimit& answers,
                              const std::function<absl::Status(ExportedFile piece)>& emit,
                              const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CLIP_EXPORT_H_
