#include <algorithm>
#include <optional>
#include <utility>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/str_cat.h"
#include "core/space/space_serialization.h"
#include "storage/blob_codec.h"
#include "storage/database.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_checks.h"
#include "storage/internal/record_rows.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::storage {
namespace {

// The skeleton a new space is stored on: `skeleton_id` when it is given (it must exist and be
// of the space's topology, whose TopologyKey is `key`), else the space's own, found or created.
absl::StatusOr<int64_t> SkeletonOfSpace(SqliteConnection& db, int64_t skeleton_id,
                                        const MotionSpace& space, const std::string& key,
                                        int64_t now) {
  if (skeleton_id == 0) return FindOrCreateSkeleton(db, space.skeleton(), key, now);
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement find,
                            db.Prepare("SELECT topology_key FROM skeletons WHERE skeleton_id = ?"));
  MOTIONDB_ASSIGN_OR_RETURN(const bool found, find.BindInt64(1, skeleton_id).Step());
  if (!found) return absl::NotFoundError(absl::StrCat("skeleton ", skeleton_id, " not found"));
  if (find.ColumnText(0) != key) {
    return absl::FailedPreconditionError(absl::StrCat("the space's skeleton differs from skeleton ",
                                                      skeleton_id, " in joint names or parents"));
  }
  return skeleton_id;
}

// Records the skeletons of a space over several: each must exist, the first be the space's own.
absl::Status InsertSkeletonsOfSpace(SqliteConnection& db, int64_t space_id, int64_t skeleton_id,
                                    const std::vector<int64_t>& skeleton_ids) {
  if (skeleton_ids.front() != skeleton_id) {
    return absl::FailedPreconditionError(absl::StrCat(
        "the space's skeleton is ", skeleton_id, ", not the first listed, ", skeleton_ids.front()));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement insert,
      db.Prepare("INSERT INTO space_skeletons (space_id, skeleton_id) VALUES (?, ?)"));
  for (const int64_t id : skeleton_ids) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool exists,
                              Exists(db, "SELECT 1 FROM skeletons WHERE skeleton_id = ?", id));
    if (!exists) return absl::NotFoundError(absl::StrCat("skeleton ", id, " not found"));
    insert.Reset();
    MOTIONDB_RETURN_IF_ERROR(insert.BindInt64(1, space_id).BindInt64(2, id).Run());
  }
  return absl::OkStatus();
}

// Inserts the new space's projections, which must be those of every clip of its skeletons.
absl::Status InsertProjectionsOfSpace(SqliteConnection& db, int64_t space_id,
                                      const std::vector<int64_t>& skeleton_ids,
                                      const std::vector<Projection>& projections) {
  // The clips of these skeletons, each of which must come with its projection.
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement clips,
                            db.Prepare("SELECT clip_id FROM clips WHERE skeleton_id = ?"));
  absl::flat_hash_set<int64_t> needed;
  for (const int64_t skeleton_id : skeleton_ids) {
    clips.Reset();
    clips.BindInt64(1, skeleton_id);
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, clips.Step());
      if (!row) break;
      needed.insert(clips.ColumnInt64(0));
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement insert_projection, PrepareProjectionInsert(db));
  for (const Projection& projection : projections) {
    if (needed.erase(projection.clip_id) == 0) {
      MOTIONDB_ASSIGN_OR_RETURN(
          const bool exists,
          Exists(db, "SELECT 1 FROM clips WHERE clip_id = ?", projection.clip_id));
      if (!exists) {
        return absl::NotFoundError(absl::StrCat("clip ", projection.clip_id, " not found"));
      }
      return absl::FailedPreconditionError(absl::StrCat(
          "clip ", projection.clip_id, " belongs to another skeleton than the space's"));
    }
    MOTIONDB_RETURN_IF_ERROR(
        InsertProjection(insert_projection, space_id, projection.clip_id, projection.coordinates));
  }
  if (!needed.empty()) {
    return absl::FailedPreconditionError(absl::StrCat(
        "no projection of clip ", *std::min_element(needed.begin(), needed.end()),
        " of the space's skeleton; a space is stored with the projections of all its clips"));
  }
  return absl::OkStatus();
}

// Fills record->skeleton_ids: the space's own skeleton first, then the others in id order.
absl::Status ReadSkeletonsOfSpace(SqliteConnection& db, SpaceRecord* record) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                            db.Prepare("SELECT skeleton_id FROM space_skeletons WHERE space_id = ? "
                                       "ORDER BY skeleton_id != ?, skeleton_id"));
  query.BindInt64(1, record->space_id).BindInt64(2, record->skeleton_id);
  record->skeleton_ids.clear();
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
    if (!row) return absl::OkStatus();
    record->skeleton_ids.push_back(query.ColumnInt64(0));
  }
}

}  // namespace

absl::StatusOr<int64_t> Database::InsertSpace(const SpaceRecord& record, const MotionSpace& space,
                                              const std::vector<Projection>& projections,
                                              const WriteOptions& write) {
  MOTIONDB_RETURN_IF_ERROR(CheckName("space name", record.name, kMaxNameBytes));
  if (record.version < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("space version must be at least 1, got ", record.version));
  }
  absl::flat_hash_set<int64_t> clip_ids;
  for (const Projection& projection : projections) {
    if (!clip_ids.insert(projection.clip_id).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("two projections of clip ", projection.clip_id));
    }
    MOTIONDB_RETURN_IF_ERROR(
        CheckProjection(projection.coordinates, space.dims(),
                        absl::StrCat("projection of clip ", projection.clip_id)));
  }
  const std::string key = TopologyKey(space.skeleton());
  const std::string data = SerializeSpace(space);
  const int64_t now = CreationTime(record.created_unix_ms);

  int64_t space_id = 0;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_RETURN_IF_ERROR(CheckNameFree(db, "spaces", "space", record.name));
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t skeleton_id,
                              SkeletonOfSpace(db, record.skeleton_id, space, key, now));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO spaces (name, skeleton_id, version, dims, created_unix_ms, data, "
                   "build_report_json) VALUES (?, ?, ?, ?, ?, ?, ?)"));
    MOTIONDB_RETURN_IF_ERROR(insert.BindText(1, record.name)
                                 .BindInt64(2, skeleton_id)
                                 .BindInt64(3, record.version)
                                 .BindInt64(4, space.dims())
                                 .BindInt64(5, now)
                                 .BindBlob(6, data)
                                 .BindText(7, record.build_report_json)
                                 .Run());
    space_id = db.last_insert_rowid();
    if (record.skeleton_ids.empty()) {
      return InsertProjectionsOfSpace(db, space_id, {skeleton_id}, projections);
    }
    MOTIONDB_RETURN_IF_ERROR(
        InsertSkeletonsOfSpace(db, space_id, skeleton_id, record.skeleton_ids));
    return InsertProjectionsOfSpace(db, space_id, record.skeleton_ids, projections);
  }));
  return space_id;
}

absl::StatusOr<SpaceRecord> Database::GetSpaceRecord(const std::string& name) {
  SpaceRecord record;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(absl::StrCat("SELECT ", kSpaceRecordColumns, " FROM spaces WHERE name = ?")));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindText(1, name).Step());
    if (!found) return absl::NotFoundError(absl::StrCat("space '", name, "' not found"));
    record = ReadSpaceRecord(query);
    return ReadSkeletonsOfSpace(db, &record);
  }));
  return record;
}

absl::StatusOr<MotionSpace> Database::GetSpace(int64_t space_id) {
  std::optional<MotionSpace> space;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              db.Prepare("SELECT data FROM spaces WHERE space_id = ?"));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindInt64(1, space_id).Step());
    if (!found) return absl::NotFoundError(absl::StrCat("space ", space_id, " not found"));
    absl::StatusOr<MotionSpace> parsed = ParseSpace(query.ColumnBlob(0));
    // Bytes this code wrote that no longer parse are damage, whatever ParseSpace calls it.
    if (!parsed.ok()) {
      return Prefixed(absl::StrCat("stored space ", space_id),
                      absl::DataLossError(parsed.status().message()));
    }
    space.emplace(*std::move(parsed));
    return absl::OkStatus();
  }));
  return *std::move(space);
}

absl::StatusOr<std::vector<SpaceRecord>> Database::ListSpaces() {
  std::vector<SpaceRecord> records;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(absl::StrCat("SELECT ", kSpaceRecordColumns, " FROM spaces ORDER BY space_id")));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) break;
      records.push_back(ReadSpaceRecord(query));
    }
    for (SpaceRecord& record : records) MOTIONDB_RETURN_IF_ERROR(ReadSkeletonsOfSpace(db, &record));
    return absl::OkStatus();
  }));
  return records;
}

absl::Status Database::DeleteSpace(const std::string& name, const WriteOptions& write) {
  return impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement erase,
                              db.Prepare("DELETE FROM spaces WHERE name = ?"));
    return DeleteRow(db, erase.BindText(1, name), absl::StrCat("space '", name, "' not found"));
  });
}

absl::StatusOr<std::vector<Projection>> Database::LoadProjections(int64_t space_id) {
  std::vector<Projection> projections;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const bool exists,
                              Exists(db, "SELECT 1 FROM spaces WHERE space_id = ?", space_id));
    if (!exists) return absl::NotFoundError(absl::StrCat("space ", space_id, " not found"));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare("SELECT clip_id, frames, dims, data FROM projections WHERE space_id = ? "
                   "ORDER BY clip_id"));
    query.BindInt64(1, space_id);
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      Projection& projection = projections.emplace_back();
      projection.clip_id = query.ColumnInt64(0);
      MOTIONDB_ASSIGN_OR_RETURN(
          projection.coordinates,
          Prefixed(absl::StrCat("space ", space_id, ", clip ", projection.clip_id),
                   ParseFloat32Blob(query.ColumnBlob(3), query.ColumnInt64(1), query.ColumnInt64(2),
                                    "projection")));
    }
  }));
  return projections;
}

}  // namespace motiondb::storage
