// The rows behind the Database's records: the column lists and decoders that turn a row into a
// ClipRecord, a Clip or a SpaceRecord, and the statements the clip and the space operations
// share (skeleton and projection rows, existence and name checks, one-row deletes).
//
// Not thread-safe: each function uses the connection or statement it is given, which belongs to
// one thread at a time (storage/sqlite_connection.h).
#ifndef MOTIONDB_STORAGE_INTERNAL_RECORD_ROWS_H_
#define MOTIONDB_STORAGE_INTERNAL_RECORD_ROWS_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"
#include "core/motion/skeleton.h"
#include "storage/database.h"
#include "storage/sqlite_connection.h"
#include "storage/sqlite_statement.h"

namespace motiondb::storage {

// The columns ReadClipRecord reads, of the clips table as `c`.
inline constexpr absl::string_view kClipRecordColumns =
    "c.clip_id, c.name, c.source_file, c.skeleton_id, c.created_unix_ms, c.frame_time, "
    "c.frame_count, c.joint_count, c.content_hash, c.provenance, "
    "coalesce((SELECT format FROM clip_sources s WHERE s.clip_id = c.clip_id), ''), "
    "coalesce((SELECT unit_m FROM clip_sources s WHERE s.clip_id = c.clip_id), 0), "
    "coalesce((SELECT up_axis FROM clip_sources s WHERE s.clip_id = c.clip_id), '')";
inline constexpr int kClipRecordColumnCount = 13;
// The columns ReadClipLayout reads, listed after kClipRecordColumns.
inline constexpr absl::string_view kClipLayoutColumns = "c.position_joint_count, c.layout";
// The columns ReadSpaceRecord reads, of the spaces table.
inline constexpr absl::string_view kSpaceRecordColumns =
    "space_id, name, skeleton_id, version, created_unix_ms, build_report_json";

// The record of a row that starts with kClipRecordColumns; its tags are read with LoadTags.
ClipRecord ReadClipRecord(const SqliteStatement& row);
// The skeleton of a row of kClipRecordColumns then kClipLayoutColumns, whose record is
// `record`. DATA_LOSS when the stored layout no longer describes the row.
absl::StatusOr<std::shared_ptr<const Skeleton>> ReadClipLayout(const SqliteStatement& row,
                                                               const ClipRecord& record);
// `frames` frames of a clip of `skeleton` from the bytes of its blobs (ParseRotationBlob's
// quaternions, float32 positions). DATA_LOSS when the bytes do not decode into such a clip.
absl::StatusOr<Clip> DecodeClipFrames(std::shared_ptr<const Skeleton> skeleton, double frame_time,
                                      absl::string_view rotations_blob,
                                      absl::string_view positions_blob, int64_t frames);
// The record of a row of kSpaceRecordColumns.
SpaceRecord ReadSpaceRecord(const SqliteStatement& row);

// "SELECT tag ... WHERE clip_id = ?", prepared once for the clips of a page.
absl::StatusOr<SqliteStatement> PrepareTagQuery(SqliteConnection& db);
// The tags of one clip, sorted, with `tags` from PrepareTagQuery.
absl::StatusOr<std::vector<std::string>> LoadTags(SqliteStatement& tags, int64_t clip_id);

// A new row's creation time: as given, or now when it is 0.
int64_t CreationTime(int64_t given_unix_ms);

// Whether `sql`, with its one parameter bound to `key`, returns a row.
absl::StatusOr<bool> Exists(SqliteConnection& db, absl::string_view sql, int64_t key);
// ALREADY_EXISTS, calling the row a `what`, when `table` ("clips" or "spaces") has a row
// called `name`.
absl::Status CheckNameFree(SqliteConnection& db, absl::string_view table, absl::string_view what,
                           absl::string_view name);

// The id of the skeleton whose TopologyKey is `key`, inserting `skeleton`'s row (created at
// `now`) when there is none.
absl::StatusOr<int64_t> FindOrCreateSkeleton(SqliteConnection& db, const Skeleton& skeleton,
                                             const std::string& key, int64_t now);

// "INSERT INTO projections ...", prepared once for the projections of one write.
absl::StatusOr<SqliteStatement> PrepareProjectionInsert(SqliteConnection& db);
// Inserts one projection row with `insert` from PrepareProjectionInsert.
absl::Status InsertProjection(SqliteStatement& insert, int64_t space_id, int64_t clip_id,
                              const RowMatrixXf& coordinates);

// Runs `erase`, a bound DELETE of one row (its foreign keys cascade) on `db`; NOT_FOUND with
// `missing` when there was no such row.
absl::Status DeleteRow(SqliteConnection& db, SqliteStatement& erase, absl::string_view missing);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_INTERNAL_RECORD_ROWS_H_
