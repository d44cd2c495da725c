// Pose models (storage/pose_model_record.h).
#include <utility>

#include "absl/strings/str_cat.h"
#include "storage/database.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_checks.h"
#include "storage/internal/record_rows.h"
#include "util/status_macros.h"

namespace motiondb::storage {
namespace {

constexpr absl::string_view kPoseModelQuery =
    "SELECT m.model_id, m.name, m.space_id, s.name, m.data, m.parameters, m.created_unix_ms "
    "FROM pose_models m JOIN spaces s ON s.space_id = m.space_id";

PoseModelRecord ReadPoseModel(const SqliteStatement& row) {
  PoseModelRecord model;
  model.model_id = row.ColumnInt64(0);
  model.name = row.ColumnText(1);
  model.space_id = row.ColumnInt64(2);
  model.space_name = row.ColumnText(3);
  model.data = row.ColumnText(4);
  model.parameters_json = row.ColumnText(5);
  model.created_unix_ms = row.ColumnInt64(6);
  return model;
}

absl::Status PoseModelNotFound(const std::string& name) {
  return absl::NotFoundError(absl::StrCat("no pose model named '", name.substr(0, 128), "'"));
}

}  // namespace

absl::StatusOr<int64_t> Database::InsertPoseModel(const PoseModelRecord& model,
                                                  const WriteOptions& write) {
  MOTIONDB_RETURN_IF_ERROR(CheckName("name", model.name, kMaxPoseModelNameBytes));
  const int64_t now = CreationTime(model.created_unix_ms);
  int64_t model_id = 0;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const bool space, Exists(db, "SELECT 1 FROM spaces WHERE space_id = ?", model.space_id));
    if (!space) return absl::NotFoundError(absl::StrCat("space ", model.space_id, " not found"));
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement taken,
                              db.Prepare("SELECT 1 FROM pose_models WHERE name = ?"));
    MOTIONDB_ASSIGN_OR_RETURN(const bool exists, taken.BindText(1, model.name).Step());
    if (exists) {
      return absl::AlreadyExistsError(
          absl::StrCat("a pose model named '", model.name, "' already exists"));
    }
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO pose_models (name, space_id, data, parameters, created_unix_ms) "
                   "VALUES (?, ?, ?, ?, ?)"));
    MOTIONDB_RETURN_IF_ERROR(insert.BindText(1, model.name)
                                 .BindInt64(2, model.space_id)
                                 .BindText(3, model.data)
                                 .BindText(4, model.parameters_json)
                                 .BindInt64(5, now)
                                 .Run());
    model_id = db.last_insert_rowid();
    return absl::OkStatus();
  }));
  return model_id;
}

absl::StatusOr<PoseModelRecord> Database::GetPoseModel(const std::string& name) {
  PoseModelRecord model;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              db.Prepare(absl::StrCat(kPoseModelQuery, " WHERE m.name = ?")));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindText(1, name).Step());
    if (!found) return PoseModelNotFound(name);
    model = ReadPoseModel(query);
    return absl::OkStatus();
  }));
  return model;
}

absl::StatusOr<std::vector<PoseModelRecord>> Database::ListPoseModels(int64_t space_id) {
  std::vector<PoseModelRecord> models;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(
            absl::StrCat(kPoseModelQuery, " WHERE ?1 = 0 OR m.space_id = ?1 ORDER BY m.name")));
    query.BindInt64(1, space_id);
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      models.push_back(ReadPoseModel(query));
    }
  }));
  return models;
}

absl::Status Database::DeletePoseModel(const std::string& name, const WriteOptions& write) {
  return impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement erase,
                              db.Prepare("DELETE FROM pose_models WHERE name = ?"));
    erase.BindText(1, name);
    return DeleteRow(db, erase, absl::StrCat("no pose model named '", name.substr(0, 128), "'"));
  });
}

}  // namespace motiondb::storage
