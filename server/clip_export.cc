#include "server/clip_export.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/bvh/bvh_writer.h"
#include "core/gltf/gltf_writer.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// A clip's selected range and the file name an export of it suggests.
struct ExportShape {
  storage::ClipLayout layout;
  FrameRange frames;
  std::string file_name;
};

absl::string_view Extension(ExportFormat format) {
  switch (format) {
    case ExportFormat::kGltf:
      return ".gltf";
    case ExportFormat::kGlb:
      return ".glb";
    case ExportFormat::kBvh:
      break;
  }
  return ".bvh";
}

absl::StatusOr<ExportShape> ShapeOfExport(storage::Database& database,
                                          const ClipSelection& selection, ExportFormat format) {
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
  shape.file_name = whole ? absl::StrCat(base, Extension(format))
                          : absl::StrCat(base, "_", shape.frames.first, "-", shape.frames.last,
                                         Extension(format));
  return shape;
}

// The BVH text of `shape`'s frames, handed to `emit` in pieces as the frames are read.
absl::Status WriteBvhPieces(storage::Database& database, ExportShape shape,
                            const std::function<absl::Status(ExportedFile piece)>& emit,
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
        ExportedFile piece;
        MOTIONDB_RETURN_IF_ERROR(writer.AppendRows(batch, std::nullopt, piece.bytes));
        return emit(std::move(piece));
      });
}

// The glTF file of `shape`'s frames, made whole (its header counts them all), then handed to
// `emit` in pieces.
absl::Status WriteGltfPieces(storage::Database& database, ExportShape shape, ExportFormat format,
                             const std::function<absl::Status(ExportedFile piece)>& emit,
                             const std::function<bool()>& should_stop) {
  std::string file;
  MOTIONDB_RETURN_IF_ERROR(
      database.ReadClipFrames(shape.layout.record.clip_id, shape.frames, shape.frames.size(),
                              [&](const Clip& frames) -> absl::Status {
                                if (should_stop())
                                  return absl::CancelledError("the export's call ended");
                                GltfWriteOptions options;
                                options.binary = format == ExportFormat::kGlb;
                                options.name = shape.layout.record.name;
                                MOTIONDB_ASSIGN_OR_RETURN(file, WriteGltf(frames, options));
                                return absl::OkStatus();
                              }));
  for (size_t at = 0; at < file.size() || at == 0; at += kExportPieceBytes) {
    if (should_stop()) return absl::CancelledError("the export's call ended");
    ExportedFile piece;
    if (at == 0) {
      piece.file_name = std::move(shape.file_name);
      piece.frames = shape.frames;
    }
    piece.bytes = file.substr(at, kExportPieceBytes);
    MOTIONDB_RETURN_IF_ERROR(emit(std::move(piece)));
  }
  return absl::OkStatus();
}

// What the export's answer may take, checked before a frame is read.
absl::Status CheckExportAnswer(const ExportShape& shape, ExportFormat format,
                               const AnswerLimit& answers, bool streamed) {
  const Skeleton& skeleton = *shape.layout.skeleton;
  const std::string what = absl::StrCat("the ", Extension(format).substr(1), " file of clip ",
                                        shape.layout.record.clip_id, "'s frames ",
                                        shape.frames.first, "..", shape.frames.last);
  if (format == ExportFormat::kBvh) {
    if (streamed) return absl::OkStatus();
    return answers.Check(
        BvhFieldBytes(skeleton, shape.frames.size()) + kAnswerFixedBytes, what,
        "export it with ExportClipStream, which streams a clip of any size (so do `motiondb "
        "export` and GET /v1/clips/{id}/bvh), or a range of it");
  }
  return answers.Check(
      TextFieldBytes(GltfBound(skeleton, shape.frames.size(),
                               static_cast<int64_t>(shape.layout.record.name.size()))) +
          kAnswerFixedBytes,
      what, "export a range of it, or the whole clip as BVH (streamed, of any size)");
}

absl::Status WritePieces(storage::Database& database, ExportShape shape, ExportFormat format,
                         const std::function<absl::Status(ExportedFile piece)>& emit,
                         const std::function<bool()>& should_stop) {
  if (format == ExportFormat::kBvh) {
    return WriteBvhPieces(database, std::move(shape), emit, should_stop);
  }
  return WriteGltfPieces(database, std::move(shape), format, emit, should_stop);
}

}  // namespace

absl::StatusOr<ExportedFile> ExportClip(storage::Database& database, const ClipSelection& selection,
                                        ExportFormat format, const AnswerLimit& answers,
                                        const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(ExportShape shape, ShapeOfExport(database, selection, format));
  MOTIONDB_RETURN_IF_ERROR(CheckExportAnswer(shape, format, answers, /*streamed=*/false));
  ExportedFile exported;
  bool first = true;
  MOTIONDB_RETURN_IF_ERROR(WritePieces(
      database, std::move(shape), format,
      [&](ExportedFile piece) {
        if (first) {
          exported = std::move(piece);
          first = false;
        } else {
          exported.bytes += piece.bytes;
        }
        return absl::OkStatus();
      },
      should_stop));
  return exported;
}

absl::Status StreamClipExport(storage::Database& database, const ClipSelection& selection,
                              ExportFormat format, const AnswerLimit& answers,
                              const std::function<absl::Status(ExportedFile piece)>& emit,
                              const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(ExportShape shape, ShapeOfExport(database, selection, format));
  MOTIONDB_RETURN_IF_ERROR(CheckExportAnswer(shape, format, answers, /*streamed=*/true));
  return WritePieces(database, std::move(shape), format, emit, should_stop);
}

}  // namespace motiondb::server
