// An open SQLite blob: RAII over sqlite3_blob, for writing one blob column of one row in pieces
// (sqlite3_blob_write), so that a large blob is never whole in memory. The row is inserted first
// with a zero blob of the final size (SqliteStatement::BindZeroBlob); the writes belong to the
// connection's open transaction.
//
// Not thread-safe: used by one thread at a time, like the connection it belongs to.
#ifndef MOTIONDB_STORAGE_SQLITE_BLOB_H_
#define MOTIONDB_STORAGE_SQLITE_BLOB_H_

#include <sqlite3.h>

#include <cstdint>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "storage/sqlite_connection.h"

namespace motiondb::storage {

class SqliteBlob {
 public:
  // The blob of `column` in the row `rowid` of `table` (names of ours, not a client's), open for
  // writing.
  static absl::StatusOr<SqliteBlob> OpenForWrite(SqliteConnection& db, const char* table,
                                                 const char* column, int64_t rowid);

  SqliteBlob(SqliteBlob&& other) noexcept;
  SqliteBlob& operator=(SqliteBlob&& other) noexcept;
  SqliteBlob(const SqliteBlob&) = delete;
  SqliteBlob& operator=(const SqliteBlob&) = delete;
  ~SqliteBlob();

  // Overwrites the blob's bytes from `offset` with `bytes`; a blob cannot grow, so the range
  // must lie within it.
  absl::Status Write(absl::string_view bytes, int64_t offset);

 private:
  SqliteBlob(sqlite3_blob* blob, sqlite3* db) : blob_(blob), db_(db) {}

  sqlite3_blob* blob_ = nullptr;
  sqlite3* db_ = nullptr;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_SQLITE_BLOB_H_
