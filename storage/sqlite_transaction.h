// A transaction on a SqliteConnection that rolls back unless committed.
//
// Not thread-safe: belongs to the thread using the connection.
#ifndef MOTIONDB_STORAGE_SQLITE_TRANSACTION_H_
#define MOTIONDB_STORAGE_SQLITE_TRANSACTION_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "storage/sqlite_connection.h"

namespace motiondb::storage {

class SqliteTransaction {
 public:
  enum class Kind {
    // BEGIN: one consistent snapshot for several reads.
    kRead,
    // BEGIN IMMEDIATE: takes the write lock at once, so that a database locked by another
    // process fails here (UNAVAILABLE after the busy timeout), before any work is done, and
    // never with a deadlock when a read would later upgrade to a write.
    kWrite,
  };

  static absl::StatusOr<SqliteTransaction> Begin(SqliteConnection& connection, Kind kind);

  SqliteTransaction(SqliteTransaction&& other) noexcept;
  SqliteTransaction& operator=(SqliteTransaction&&) = delete;
  SqliteTransaction(const SqliteTransaction&) = delete;
  SqliteTransaction& operator=(const SqliteTransaction&) = delete;
  // Rolls back a transaction still open: one not committed, or whose COMMIT failed.
  ~SqliteTransaction();

  absl::Status Commit();

 private:
  explicit SqliteTransaction(SqliteConnection* connection) : connection_(connection) {}

  SqliteConnection* connection_;  // null once moved from
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_SQLITE_TRANSACTION_H_
