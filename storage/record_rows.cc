#include "storage/internal/record_rows.h"

#include <chrono>
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "storage/blob_codec.h"
#include "util/status_macros.h"

namespace motiondb::storage {

ClipRecord ReadClipRecord(const SqliteStatement& row) {
  ClipRecord record;
  record.clip_id = row.ColumnInt64(0);
  record.name = row.ColumnText(1);
  record.source_file = row.ColumnText(2);
  record.skeleton_id = row.ColumnInt64(3);
  record.created_unix_ms = row.ColumnInt64(4);
  record.frame_time = row.ColumnDouble(5);
  record.frame_count = row.ColumnInt64(6);
  record.joint_count = static_cast<int>(row.ColumnInt64(7));
  record.content_hash = row.ColumnText(8);
  record.provenance = row.ColumnText(9);
  record.source_facts.format = row.ColumnText(10);
  record.source_facts.unit_m = row.ColumnDouble(11);
  record.source_facts.up_axis = row.ColumnText(12);
  return record;
}

absl::StatusOr<std::shared_ptr<const Skeleton>> ReadClipLayout(const SqliteStatement& row,
                                                               const ClipRecord& record) {
  // kClipLayoutColumns follow the record's.
  constexpr int kFirst = kClipRecordColumnCount;
  const int64_t position_joints = row.ColumnInt64(kFirst);
  absl::StatusOr<std::shared_ptr<const Skeleton>> skeleton =
      ParseSkeletonLayout(row.ColumnBlob(kFirst + 1));
  // Bytes this code wrote that no longer parse are damage, whatever the parser calls it.
  if (!skeleton.ok()) return absl::DataLossError(skeleton.status().message());
  if ((*skeleton)->joint_count() != record.joint_count ||
      (*skeleton)->position_joint_count() != position_joints) {
    return absl::DataLossError("its layout does not match its row");
  }
  return skeleton;
}

absl::StatusOr<Clip> DecodeClipFrames(std::shared_ptr<const Skeleton> skeleton, double frame_time,
                                      absl::string_view rotations_blob,
                                      absl::string_view positions_blob, int64_t frames) {
  MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXd rotations,
                            ParseRotationBlob(rotations_blob, frames, skeleton->joint_count()));
  MOTIONDB_ASSIGN_OR_RETURN(
      const RowMatrixXf positions,
      ParseFloat32Blob(positions_blob, frames, 3 * skeleton->position_joint_count(), "positions"));
  absl::StatusOr<Clip> clip =
      Clip::Create(std::move(skeleton), frame_time, std::move(rotations), positions.cast<double>());
  if (!clip.ok()) return absl::DataLossError(clip.status().message());
  return clip;
}

SpaceRecord ReadSpaceRecord(const SqliteStatement& row) {
  SpaceRecord record;
  record.space_id = row.ColumnInt64(0);
  record.name = row.ColumnText(1);
  record.skeleton_id = row.ColumnInt64(2);
  record.version = static_cast<int>(row.ColumnInt64(3));
  record.created_unix_ms = row.ColumnInt64(4);
  record.build_report_json = row.ColumnText(5);
  return record;
}

absl::StatusOr<SqliteStatement> PrepareTagQuery(SqliteConnection& db) {
  return db.Prepare("SELECT tag FROM clip_tags WHERE clip_id = ? ORDER BY tag");
}

absl::StatusOr<std::vector<std::string>> LoadTags(SqliteStatement& tags, int64_t clip_id) {
  tags.Reset();
  tags.BindInt64(1, clip_id);
  std::vector<std::string> result;
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, tags.Step());
    if (!row) return result;
    result.push_back(tags.ColumnText(0));
  }
}

int64_t CreationTime(int64_t given_unix_ms) {
  if (given_unix_ms > 0) return given_unix_ms;
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

absl::StatusOr<bool> Exists(SqliteConnection& db, absl::string_view sql, int64_t key) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query, db.Prepare(sql));
  return query.BindInt64(1, key).Step();
}

absl::Status CheckNameFree(SqliteConnection& db, absl::string_view table, absl::string_view what,
                           absl::string_view name) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                            db.Prepare(absl::StrCat("SELECT 1 FROM ", table, " WHERE name = ?")));
  MOTIONDB_ASSIGN_OR_RETURN(const bool taken, query.BindText(1, name).Step());
  if (taken) {
    return absl::AlreadyExistsError(absl::StrCat("a ", what, " named '", name, "' already exists"));
  }
  return absl::OkStatus();
}

absl::StatusOr<int64_t> FindOrCreateSkeleton(SqliteConnection& db, const Skeleton& skeleton,
                                             const std::string& key, int64_t now) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement find,
                            db.Prepare("SELECT skeleton_id FROM skeletons WHERE topology_key = ?"));
  MOTIONDB_ASSIGN_OR_RETURN(const bool found, find.BindText(1, key).Step());
  if (found) return find.ColumnInt64(0);
  std::vector<std::string> names;
  std::vector<int> parents;
  for (const Joint& joint : skeleton.joints()) {
    names.push_back(joint.name);
    parents.push_back(joint.parent);
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement insert,
      db.Prepare("INSERT INTO skeletons (topology_key, joint_count, joint_names, joint_parents, "
                 "created_unix_ms) VALUES (?, ?, ?, ?, ?)"));
  MOTIONDB_RETURN_IF_ERROR(insert.BindText(1, key)
                               .BindInt64(2, skeleton.joint_count())
                               .BindText(3, absl::StrJoin(names, "\n"))
                               .BindText(4, absl::StrJoin(parents, ","))
                               .BindInt64(5, now)
                               .Run());
  return db.last_insert_rowid();
}

absl::StatusOr<SqliteStatement> PrepareProjectionInsert(SqliteConnection& db) {
  return db.Prepare(
      "INSERT INTO projections (space_id, clip_id, frames, dims, data) VALUES (?, ?, ?, ?, ?)");
}

absl::Status InsertProjection(SqliteStatement& insert, int64_t space_id, int64_t clip_id,
                              const RowMatrixXf& coordinates) {
  const std::string data = Float32Blob(coordinates);
  insert.Reset();
  return insert.BindInt64(1, space_id)
      .BindInt64(2, clip_id)
      .BindInt64(3, coordinates.rows())
      .BindInt64(4, coordinates.cols())
      .BindBlob(5, data)
      .Run();
}

absl::Status DeleteRow(SqliteConnection& db, SqliteStatement& erase, absl::string_view missing) {
  MOTIONDB_RETURN_IF_ERROR(erase.Run());
  if (db.changes() == 0) return absl::NotFoundError(missing);
  return absl::OkStatus();
}

}  // namespace motiondb::storage
