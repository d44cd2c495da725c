#include "storage/sqlite_statement.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "storage/sqlite_status.h"

namespace motiondb::storage {

absl::StatusOr<SqliteStatement> SqliteStatement::Prepare(sqlite3* db, absl::string_view sql) {
  sqlite3_stmt* stmt = nullptr;
  const int rc = sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &stmt, nullptr);
  if (rc != SQLITE_OK) {
    return SqliteStatus(db, rc, absl::StrCat("preparing '", sql.substr(0, 60), "'"));
  }
  return SqliteStatement(stmt);
}

SqliteStatement::SqliteStatement(SqliteStatement&& other) noexcept
    : stmt_(std::exchange(other.stmt_, nullptr)), bind_status_(std::move(other.bind_status_)) {}

SqliteStatement& SqliteStatement::operator=(SqliteStatement&& other) noexcept {
  if (this != &other) {
    sqlite3_finalize(stmt_);
    stmt_ = std::exchange(other.stmt_, nullptr);
    bind_status_ = std::move(other.bind_status_);
  }
  return *this;
}

SqliteStatement::~SqliteStatement() { sqlite3_finalize(stmt_); }

SqliteStatement& SqliteStatement::Check(int rc, int index) {
  if (rc != SQLITE_OK && bind_status_.ok()) {
    bind_status_ = SqliteStatus(sqlite3_db_handle(stmt_), rc,
                                absl::StrCat("binding parameter ", index, " of ", Context()));
  }
  return *this;
}

SqliteStatement& SqliteStatement::BindInt64(int index, int64_t value) {
  return Check(sqlite3_bind_int64(stmt_, index, value), index);
}

SqliteStatement& SqliteStatement::BindDouble(int index, double value) {
  return Check(sqlite3_bind_double(stmt_, index, value), index);
}

SqliteStatement& SqliteStatement::BindText(int index, absl::string_view text) {
  // A null pointer would bind NULL rather than the empty string.
  return Check(sqlite3_bind_text64(stmt_, index, text.empty() ? "" : text.data(), text.size(),
                                   SQLITE_TRANSIENT, SQLITE_UTF8),
               index);
}

SqliteStatement& SqliteStatement::BindBlob(int index, absl::string_view bytes) {
  if (bytes.empty()) return Check(sqlite3_bind_zeroblob(stmt_, index, 0), index);
  return Check(sqlite3_bind_blob64(stmt_, index, bytes.data(), bytes.size(), SQLITE_STATIC), index);
}

SqliteStatement& SqliteStatement::BindZeroBlob(int index, int64_t bytes) {
  return Check(sqlite3_bind_zeroblob64(stmt_, index, static_cast<sqlite3_uint64>(bytes)), index);
}

absl::StatusOr<bool> SqliteStatement::Step() {
  if (!bind_status_.ok()) return bind_status_;
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  return SqliteStatus(sqlite3_db_handle(stmt_), rc, Context());
}

absl::Status SqliteStatement::Run() {
  absl::StatusOr<bool> row = Step();
  if (!row.ok()) return row.status();
  if (*row) return absl::InternalError(absl::StrCat(Context(), " returned a row"));
  return absl::OkStatus();
}

void SqliteStatement::Reset() {
  // sqlite3_reset repeats the last step's error, which Step() already reported.
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
  bind_status_ = absl::OkStatus();
}

int64_t SqliteStatement::ColumnInt64(int index) const { return sqlite3_column_int64(stmt_, index); }

double SqliteStatement::ColumnDouble(int index) const {
  return sqlite3_column_double(stmt_, index);
}

std::string SqliteStatement::ColumnText(int index) const {
  const unsigned char* text = sqlite3_column_text(stmt_, index);
  const int size = sqlite3_column_bytes(stmt_, index);
  if (text == nullptr) return "";
  return std::string(reinterpret_cast<const char*>(text), size);
}

absl::string_view SqliteStatement::ColumnBlob(int index) const {
  // sqlite3_column_blob must come before sqlite3_column_bytes (SQLite's documented order).
  const void* bytes = sqlite3_column_blob(stmt_, index);
  const int size = sqlite3_column_bytes(stmt_, index);
  if (bytes == nullptr) return {};  // an empty blob
  return absl::string_view(static_cast<const char*>(bytes), size);
}

std::string SqliteStatement::Context() const {
  const char* sql = sqlite3_sql(stmt_);
  return absl::StrCat("'", absl::string_view(sql ? sql : "").substr(0, 60), "'");
}

}  // namespace motiondb::storage
