#include "storage/sqlite_transaction.h"

#include <utility>

#include "util/status_macros.h"

namespace motiondb::storage {

absl::StatusOr<SqliteTransaction> SqliteTransaction::Begin(SqliteConnection& connection,
                                                           Kind kind) {
  MOTIONDB_RETURN_IF_ERROR(connection.Execute(kind == Kind::kWrite ? "BEGIN IMMEDIATE" : "BEGIN"));
  return SqliteTransaction(&connection);
}

SqliteTransaction::SqliteTransaction(SqliteTransaction&& other) noexcept
    : connection_(std::exchange(other.connection_, nullptr)) {}

SqliteTransaction::~SqliteTransaction() {
  // Autocommit mode means no transaction is open: committed, or already rolled back by SQLite
  // itself (as it does after some I/O errors).
  if (connection_ != nullptr && sqlite3_get_autocommit(connection_->handle()) == 0) {
    // Nothing to do if even the rollback fails: SQLite rolls back a hot journal or ignores
    // uncommitted WAL frames when the file is next opened.
    (void)connection_->Execute("ROLLBACK");
  }
}

absl::Status SqliteTransaction::Commit() { return connection_->Execute("COMMIT"); }

}  // namespace motiondb::storage
