// One SQLite connection (RAII over sqlite3*), with extended result codes and a busy timeout.
//
// Not thread-safe: a connection is used by one thread at a time (the Database's writer under
// its mutex, a reader while it holds the connection's ReadPool lease), so it is opened with
// SQLITE_OPEN_NOMUTEX.
#ifndef MOTIONDB_STORAGE_SQLITE_CONNECTION_H_
#define MOTIONDB_STORAGE_SQLITE_CONNECTION_H_

#include <sqlite3.h>

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "storage/sqlite_statement.h"

namespace motiondb::storage {

class SqliteConnection {
 public:
  enum class Mode { kReadOnly, kReadWrite, kReadWriteCreate };

  // Opens `path` (a plain file name: URIs are not interpreted). `busy_timeout_ms`: how long a
  // statement waits for another connection's lock before failing with SQLITE_BUSY.
  // FAILED_PRECONDITION when a writable mode is asked of a file that opens read-only.
  static absl::StatusOr<std::unique_ptr<SqliteConnection>> Open(const std::string& path, Mode mode,
                                                                int busy_timeout_ms);
  SqliteConnection(const SqliteConnection&) = delete;
  SqliteConnection& operator=(const SqliteConnection&) = delete;
  ~SqliteConnection();

  sqlite3* handle() const { return db_; }
  absl::StatusOr<SqliteStatement> Prepare(absl::string_view sql) {
    return SqliteStatement::Prepare(db_, sql);
  }
  // Runs one or more statements without parameters, ignoring any rows they return.
  absl::Status Execute(const std::string& sql);
  // The first column of the first row of `sql`, e.g. a PRAGMA's answer; NOT_FOUND when the
  // statement returns no row.
  absl::StatusOr<std::string> QueryText(absl::string_view sql);
  absl::StatusOr<int64_t> QueryInt64(absl::string_view sql);

  // The rowid of the row that the last successful INSERT on this connection added (0 before
  // any), e.g. the id AUTOINCREMENT assigned.
  int64_t last_insert_rowid() const;
  // How many rows the last INSERT, UPDATE or DELETE on this connection changed itself, not
  // counting those of foreign key cascades or triggers; a DELETE that matched nothing gives 0.
  int64_t changes() const;

 private:
  explicit SqliteConnection(sqlite3* db) : db_(db) {}
  // `sql` prepared and stepped to its first row.
  absl::StatusOr<SqliteStatement> QueryRow(absl::string_view sql);

  sqlite3* db_;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_SQLITE_CONNECTION_H_
