// An open SQLite blob: RAII over sqlite3_blob, for reading or writing one blob column of one row
// in pieces (sqlite3_blob_read / sqlite3_blob_write), so that a large blob is never whole in
// memory. To write one, insert or update its row with a zero blob of the final size first
// (SqliteStatement::BindZeroBlob). The handle belongs to the connection's open transaction and
// must be destroyed before it commits (SQLite refuses a commit while a write handle is open).
//
// Not thread-safe: used by one thread at a time, like the connection it belongs to.
#ifndef MOTIONDB_STORAGE_SQLITE_BLOB_H_
#define MOTIONDB_STORAGE_SQLITE_BLOB_H_

#include <sqlite3.h>

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "storage/sqlite_connection.h"

namespace motiondb::storage {

class SqliteBlob {
 public:
  enum class Mode { kRead, kWrite };

  // The blob of `column` in the row `rowid` of `table` (names of ours, not a client's).
  static absl::StatusOr<SqliteBlob> Open(SqliteConnection& db, const char* table,
                                         const char* column, int64_t rowid, Mode mode);

  SqliteBlob(SqliteBlob&& other) noexcept;
  SqliteBlob& operator=(SqliteBlob&& other) noexcept;
  SqliteBlob(const SqliteBlob&) = delete;
  SqliteBlob& operator=(const SqliteBlob&) = delete;
  ~SqliteBlob();

  int64_t size() const { return sqlite3_blob_bytes(blob_); }
  // `bytes` bytes from `offset` into `out` (replacing its contents). The range must lie within
  // the blob, as it must for Write: a blob cannot grow.
  absl::Status Read(int64_t offset, int64_t bytes, std::string& out);
  // Overwrites the blob's bytes from `offset` with `bytes`.
  absl::Status Write(absl::string_view bytes, int64_t offset);

 private:
  SqliteBlob(sqlite3_blob* blob, sqlite3* db) : blob_(blob), db_(db) {}
  // OUT_OF_RANGE unless [offset, offset + bytes) lies within the blob.
  absl::Status CheckRange(int64_t offset, int64_t bytes) const;

  sqlite3_blob* blob_ = nullptr;
  sqlite3* db_ = nullptr;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_SQLITE_BLOB_H_
