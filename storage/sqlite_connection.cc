#include "storage/sqlite_connection.h"

#include "absl/strings/str_cat.h"
#include "storage/sqlite_status.h"
#include "util/status_macros.h"

namespace motiondb::storage {

absl::StatusOr<std::unique_ptr<SqliteConnection>> SqliteConnection::Open(const std::string& path,
                                                                         Mode mode,
                                                                         int busy_timeout_ms) {
  int flags = SQLITE_OPEN_NOMUTEX;
  switch (mode) {
    case Mode::kReadOnly:
      flags |= SQLITE_OPEN_READONLY;
      break;
    case Mode::kReadWrite:
      flags |= SQLITE_OPEN_READWRITE;
      break;
    case Mode::kReadWriteCreate:
      flags |= SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
      break;
  }
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &db, flags, nullptr);
  // sqlite3_open_v2 hands out a connection even on failure, to carry the error message.
  std::unique_ptr<SqliteConnection> connection(new SqliteConnection(db));
  if (rc != SQLITE_OK) return SqliteStatus(db, rc, absl::StrCat("opening '", path, "'"));
  // SQLite opens a file it may not write read-only without an error; every write would fail.
  if (mode != Mode::kReadOnly && sqlite3_db_readonly(db, "main") == 1) {
    return absl::FailedPreconditionError(
        "the file can only be opened read-only (a read-only file system or the file's "
        "permissions), and it was opened to be written");
  }
  sqlite3_extended_result_codes(db, 1);
  sqlite3_busy_timeout(db, busy_timeout_ms);
  return connection;
}

SqliteConnection::~SqliteConnection() {
  // close_v2 defers the close, rather than failing, should a statement still be alive.
  sqlite3_close_v2(db_);
}

absl::Status SqliteConnection::Execute(const std::string& sql) {
  const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr);
  if (rc != SQLITE_OK) {
    return SqliteStatus(db_, rc, absl::StrCat("running '", sql.substr(0, 60), "'"));
  }
  return absl::OkStatus();
}

int64_t SqliteConnection::last_insert_rowid() const { return sqlite3_last_insert_rowid(db_); }

int64_t SqliteConnection::changes() const { return sqlite3_changes64(db_); }

absl::StatusOr<SqliteStatement> SqliteConnection::QueryRow(absl::string_view sql) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement statement, Prepare(sql));
  MOTIONDB_ASSIGN_OR_RETURN(const bool row, statement.Step());
  if (!row) return absl::NotFoundError(absl::StrCat("'", sql, "' returned no row"));
  return statement;
}

absl::StatusOr<std::string> SqliteConnection::QueryText(absl::string_view sql) {
  MOTIONDB_ASSIGN_OR_RETURN(const SqliteStatement statement, QueryRow(sql));
  return statement.ColumnText(0);
}

absl::StatusOr<int64_t> SqliteConnection::QueryInt64(absl::string_view sql) {
  MOTIONDB_ASSIGN_OR_RETURN(const SqliteStatement statement, QueryRow(sql));
  return statement.ColumnInt64(0);
}

}  // namespace motiondb::storage
