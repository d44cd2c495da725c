// A clip's layout without its frames, and its frames read in batches through blob handles
// (storage/sqlite_blob.h): what an answer about a long clip is sized by, and what a streamed
// export reads without holding the clip.
#include <algorithm>
#include <optional>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "storage/database.h"
#include "storage/internal/clip_frames.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_rows.h"
#include "storage/sqlite_blob.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::storage {
namespace {

// Bytes a frame takes in each blob: a float32 quaternion a joint, a float32 vector a position
// joint (storage/blob_codec.h).
constexpr int64_t kRotationBytes = 16;
constexpr int64_t kPositionBytes = 12;

absl::StatusOr<ClipLayout> ReadLayout(SqliteConnection& db, int64_t clip_id) {
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement query,
      db.Prepare(absl::StrCat("SELECT ", kClipRecordColumns, ", ", kClipLayoutColumns,
                              " FROM clips c WHERE c.clip_id = ?")));
  query.BindInt64(1, clip_id);
  MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("clip ", clip_id, " not found"));
  ClipLayout layout;
  layout.record = ReadClipRecord(query);
  MOTIONDB_ASSIGN_OR_RETURN(layout.skeleton, Prefixed(absl::StrCat("stored clip ", clip_id),
                                                      ReadClipLayout(query, layout.record)));
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement tags, PrepareTagQuery(db));
  MOTIONDB_ASSIGN_OR_RETURN(layout.record.tags, LoadTags(tags, clip_id));
  return layout;
}

// One of the clip's frame blobs, `bytes_per_frame` a frame; DATA_LOSS when its size is not that
// of the clip's frames.
absl::StatusOr<SqliteBlob> OpenFrameBlob(SqliteConnection& db, const ClipRecord& record,
                                         const char* column, int64_t bytes_per_frame) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteBlob blob, SqliteBlob::Open(db, "clips", column, record.clip_id,
                                                              SqliteBlob::Mode::kRead));
  if (blob.size() != record.frame_count * bytes_per_frame) {
    return absl::DataLossError(absl::StrCat("stored clip ", record.clip_id, ": its ", column,
                                            " hold ", blob.size(), " bytes, not ",
                                            record.frame_count * bytes_per_frame));
  }
  return blob;
}

// A clip's frames read from its blobs a range at a time, only the range's bytes each (a blob's
// substr() reads the whole blob, however short the range).
class FrameReader {
 public:
  // For the frames `frames` of the clip of `layout`: OUT_OF_RANGE when they are not inside it.
  static absl::StatusOr<FrameReader> Open(SqliteConnection& db, const ClipLayout& layout,
                                          FrameRange frames) {
    const ClipRecord& record = layout.record;
    MOTIONDB_RETURN_IF_ERROR(Prefixed(absl::StrCat("stored clip ", record.clip_id),
                                      CheckFrameRange(frames, record.frame_count)));
    FrameReader reader(layout);
    MOTIONDB_ASSIGN_OR_RETURN(reader.rotations_,
                              OpenFrameBlob(db, record, "rotations", reader.rotation_bytes_));
    // A skeleton without translation channels stores no positions (and an empty blob, which
    // need not open).
    if (reader.position_bytes_ > 0) {
      MOTIONDB_ASSIGN_OR_RETURN(reader.positions_,
                                OpenFrameBlob(db, record, "positions", reader.position_bytes_));
    }
    return reader;
  }

  // `count` frames from frame `first`, inside the range Open was given.
  absl::StatusOr<Clip> Read(int64_t first, int64_t count) {
    MOTIONDB_RETURN_IF_ERROR(
        rotations_->Read(first * rotation_bytes_, count * rotation_bytes_, rotation_piece_));
    if (positions_) {
      MOTIONDB_RETURN_IF_ERROR(
          positions_->Read(first * position_bytes_, count * position_bytes_, position_piece_));
    }
    return Prefixed(absl::StrCat("stored clip ", layout_.record.clip_id, " at frame ", first),
                    DecodeClipFrames(layout_.skeleton, layout_.record.frame_time, rotation_piece_,
                                     position_piece_, count));
  }

 private:
  explicit FrameReader(const ClipLayout& layout)
      : layout_(layout),
        rotation_bytes_(kRotationBytes * layout.record.joint_count),
        position_bytes_(kPositionBytes * layout.skeleton->position_joint_count()) {}

  const ClipLayout& layout_;
  int64_t rotation_bytes_, position_bytes_;
  std::optional<SqliteBlob> rotations_, positions_;
  std::string rotation_piece_, position_piece_;  // reused from range to range
};

}  // namespace

absl::StatusOr<ClipLayout> Database::GetClipLayout(int64_t clip_id) {
  std::optional<ClipLayout> layout;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(layout, ReadLayout(db, clip_id));
    return absl::OkStatus();
  }));
  return *std::move(layout);
}

absl::Status Database::ReadClipFrames(int64_t clip_id, FrameRange frames, int batch_frames,
                                      const std::function<absl::Status(const Clip&)>& consume) {
  if (batch_frames < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("batch_frames = ", batch_frames, "; expected at least 1"));
  }
  return impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const ClipLayout layout, ReadLayout(db, clip_id));
    MOTIONDB_ASSIGN_OR_RETURN(FrameReader reader, FrameReader::Open(db, layout, frames));
    for (int64_t first = frames.first; first <= frames.last; first += batch_frames) {
      const int64_t count = std::min<int64_t>(batch_frames, frames.last - first + 1);
      MOTIONDB_ASSIGN_OR_RETURN(const Clip batch, reader.Read(first, count));
      MOTIONDB_RETURN_IF_ERROR(consume(batch));
    }
    return absl::OkStatus();
  });
}

absl::StatusOr<StoredClip> ReadStoredClip(SqliteConnection& db, int64_t clip_id,
                                          std::optional<FrameRange> frames) {
  MOTIONDB_ASSIGN_OR_RETURN(ClipLayout layout, ReadLayout(db, clip_id));
  const int64_t frame_count = layout.record.frame_count;
  if (!frames && frame_count == 0) {  // a BVH may say "Frames: 0"; there is no range to read
    MOTIONDB_ASSIGN_OR_RETURN(
        Clip clip, DecodeClipFrames(layout.skeleton, layout.record.frame_time, "", "", 0));
    return StoredClip{std::move(layout.record), std::move(clip)};
  }
  const FrameRange range = frames.value_or(FrameRange{0, static_cast<int>(frame_count - 1)});
  MOTIONDB_ASSIGN_OR_RETURN(FrameReader reader, FrameReader::Open(db, layout, range));
  MOTIONDB_ASSIGN_OR_RETURN(Clip clip, reader.Read(range.first, range.size()));
  return StoredClip{std::move(layout.record), std::move(clip)};
}

}  // namespace motiondb::storage
