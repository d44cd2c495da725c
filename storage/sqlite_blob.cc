#include "storage/sqlite_blob.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "storage/sqlite_status.h"

namespace motiondb::storage {

absl::StatusOr<SqliteBlob> SqliteBlob::Open(SqliteConnection& db, const char* table,
                                            const char* column, int64_t rowid, Mode mode) {
  sqlite3_blob* blob = nullptr;
  const int rc = sqlite3_blob_open(db.handle(), "main", table, column, rowid,
                                   mode == Mode::kWrite ? 1 : 0, &blob);
  if (rc != SQLITE_OK) {
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

absl::Status SqliteBlob::CheckRange(int64_t offset, int64_t bytes) const {
  if (offset < 0 || bytes < 0 || offset > size() || bytes > size() - offset) {
    return absl::OutOfRangeError(
        absl::StrCat(bytes, " bytes at ", offset, " of a blob of ", size()));
  }
  return absl::OkStatus();
}

absl::Status SqliteBlob::Read(int64_t offset, int64_t bytes, std::string& out) {
  if (absl::Status range = CheckRange(offset, bytes); !range.ok()) return range;
  out.resize(static_cast<size_t>(bytes));
  // Blobs are at most SQLITE_MAX_LENGTH (1e9) bytes, so a checked range fits an int.
  const int rc =
      sqlite3_blob_read(blob_, out.data(), static_cast<int>(bytes), static_cast<int>(offset));
  if (rc != SQLITE_OK) return SqliteStatus(db_, rc, absl::StrCat("reading a blob at ", offset));
  return absl::OkStatus();
}

absl::Status SqliteBlob::Write(absl::string_view bytes, int64_t offset) {
  const int64_t count = static_cast<int64_t>(bytes.size());
  if (absl::Status range = CheckRange(offset, count); !range.ok()) return range;
  const int rc =
      sqlite3_blob_write(blob_, bytes.data(), static_cast<int>(count), static_cast<int>(offset));
  if (rc != SQLITE_OK) return SqliteStatus(db_, rc, absl::StrCat("writing a blob at ", offset));
  return absl::OkStatus();
}

}  // namespace motiondb::storage
