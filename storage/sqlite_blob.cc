#include "storage/sqlite_blob.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "storage/sqlite_status.h"

namespace motiondb::storage {

absl::StatusOr<SqliteBlob> SqliteBlob::OpenForWrite(SqliteConnection& db, const char* table,
                                                    const char* column, int64_t rowid) {
  sqlite3_blob* blob = nullptr;
  const int rc = sqlite3_blob_open(db.handle(), "main", table, column, rowid, /*flags=*/1, &blob);
  if (rc != SQLITE_OK) {
    sqlite3_blob_close(blob);  // sqlite3_blob_open may leave a handle to close even on failure
    return SqliteStatus(db.handle(), rc,
                        absl::StrCat("opening ", table, ".", column, " of row ", rowid));
  }
  return SqliteBlob(blob, db.handle());
}

SqliteBlob::SqliteBlob(SqliteBlob&& other) noexcept
    : blob_(std::exchange(other.blob_, nullptr)), db_(other.db_) {}

SqliteBlob& SqliteBlob::operator=(SqliteBlob&& other) noexcept {
  if (this != &other) {
    sqlite3_blob_close(blob_);
    blob_ = std::exchange(other.blob_, nullptr);
    db_ = other.db_;
  }
  return *this;
}

SqliteBlob::~SqliteBlob() { sqlite3_blob_close(blob_); }

absl::Status SqliteBlob::Write(absl::string_view bytes, int64_t offset) {
  const int64_t size = sqlite3_blob_bytes(blob_);
  if (offset < 0 || offset > size || static_cast<int64_t>(bytes.size()) > size - offset) {
    return absl::OutOfRangeError(
        absl::StrCat("writing ", bytes.size(), " bytes at ", offset, " into a blob of ", size));
  }
  const int rc = sqlite3_blob_write(blob_, bytes.data(), static_cast<int>(bytes.size()),
                                    static_cast<int>(offset));
  if (rc != SQLITE_OK) {
    return SqliteStatus(db_, rc, absl::StrCat("writing ", bytes.size(), " bytes of a blob"));
  }
  return absl::OkStatus();
}

}  // namespace motiondb::storage
