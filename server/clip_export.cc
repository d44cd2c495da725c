#include "server/clip_export.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/bvh/bvh_writer.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// A clip's selected range and the file name an export of it suggests.
struct ExportShape {
  storage::ClipLayout layout;
  FrameRange frames;
  std::string file_name;
};

absl::StatusOr<ExportShape> ShapeOfExport(storage::Database& database,
                                          const ClipSelection& selection) {
  ExportShape shape;
  MOTIONDB_ASSIGN_OR_RETURN(shape.layout, database.GetClipLayout(selection.clip_id));
  const storage::ClipRecord& record = shape.layout.record;
  MOTIONDB_ASSIGN_OR_RETURN(
      shape.frames, ResolveFrameRange(selection, static_cast<int>(record.frame_count), "clip"));
  const bool whole = shape.frames.first == 0 && shape.frames.last == record.frame_count - 1;
  // A clip name's '/' separates folders ("session1/take_001"); the suggestion stays one file
  // name, which a client can write into any folder without making or leaving folders. A
  // backslash too, which separates folders on Windows.
  const std::string base = absl::StrReplaceAll(record.name, {{"/", "_"}, {"\\", "_"}});
  shape.file_name =
      whole ? absl::StrCat(base, ".bvh")
            : absl::StrCat(base, "_", shape.frames.first, "-", shape.frames.last, ".bvh");
  return shape;
}

// The text of `shape`'s frames, handed to `emit` in pieces (StreamClipExport).
absl::Status WritePieces(storage::Database& database, ExportShape shape,
                         const std::function<absl::Status(ExportedBvh piece)>& emit,
                         const std::function<bool()>& should_stop) {
  BvhStreamWriter writer(shape.layout.skeleton, kBvhAnswerThreads);
  MOTIONDB_RETURN_IF_ERROR(
      emit({std::move(shape.file_name),
            writer.Header(shape.frames.size(), shape.layout.record.frame_time), shape.frames}));
  // A batch's text is at most kExportPieceBytes, however long its numbers.
  const int batch_frames = static_cast<int>(
      std::max<int64_t>(1, kExportPieceBytes / BvhRowBound(*shape.layout.skeleton)));
  return database.ReadClipFrames(
      shape.layout.record.clip_id, shape.frames, batch_frames,
      [&](const Clip& batch) -> absl::Status {
        if (should_stop()) return absl::CancelledError("the export's call ended");
        ExportedBvh piece;
        MOTIONDB_RETURN_IF_ERROR(writer.AppendRows(batch, std::nullopt, piece.bvh));
        return emit(std::move(piece));
      });
}

}  // namespace

absl::StatusOr<ExportedBvh> ExportClip(storage::Database& database, const ClipSelection& selection,
                                       const AnswerLimit& answers,
                                       const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(ExportShape shape, ShapeOfExport(database, selection));
  MOTIONDB_RETURN_IF_ERROR(answers.Check(
      BvhFieldBytes(*shape.layout.skeleton, shape.frames.size()) + kAnswerFixedBytes,
      absl::StrCat("the BVH of clip ", selection.clip_id, "'s frames ", shape.frames.first, "..",
                   shape.frames.last),
      "export it with ExportClipStream, which streams a clip of any size (so do `motiondb "
      "export` and GET /v1/clips/{id}/bvh), or a range of it"));
  ExportedBvh exported;
  bool first = true;
  MOTIONDB_RETURN_IF_ERROR(WritePieces(
      database, std::move(shape),
      [&](ExportedBvh piece) {
        if (first) {
          exported = std::move(piece);
          first = false;
        } else {
          exported.bvh += piece.bvh;
        }
        return absl::OkStatus();
      },
      should_stop));
  return exported;
}

absl::Status StreamClipExport(storage::Database& database, const ClipSelection& selection,
                              const std::function<absl::Status(ExportedBvh piece)>& emit,
                              const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(ExportShape shape, ShapeOfExport(database, selection));
  return WritePieces(database, std::move(shape), emit, should_stop);
}

}  // namespace motiondb::server
