// A prepared SQLite statement: RAII over sqlite3_stmt, typed binds and columns, Status errors.
//
// Binds chain and remember their first error, which the next Step() reports, so that a
// statement reads as one expression: stmt.BindInt64(1, id).BindText(2, name).Run().
//
// Not thread-safe: used by one thread at a time, like the connection it belongs to.
#ifndef MOTIONDB_STORAGE_SQLITE_STATEMENT_H_
#define MOTIONDB_STORAGE_SQLITE_STATEMENT_H_

#include <sqlite3.h>

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb::storage {

class SqliteStatement {
 public:
  // Compiles the single statement `sql` on `db`.
  static absl::StatusOr<SqliteStatement> Prepare(sqlite3* db, absl::string_view sql);

  SqliteStatement(SqliteStatement&& other) noexcept;
  SqliteStatement& operator=(SqliteStatement&& other) noexcept;
  SqliteStatement(const SqliteStatement&) = delete;
  SqliteStatement& operator=(const SqliteStatement&) = delete;
  ~SqliteStatement();

  // Parameters count from 1, as in SQL. Text is copied; a blob is not (it can be megabytes),
  // so its bytes must stay alive until the statement is reset or destroyed.
  SqliteStatement& BindInt64(int index, int64_t value);
  SqliteStatement& BindDouble(int index, double value);
  SqliteStatement& BindText(int index, absl::string_view text);
  SqliteStatement& BindBlob(int index, absl::string_view bytes);
  // A blob of `bytes` zeros, which SQLite keeps as a count, not bytes, when it is the row's last
  // column; SqliteBlob writes its bytes afterwards. Bound, not written as zeroblob(?) in the
  // SQL: with a CHECK or a trigger on the column SQLite expands the SQL function's result
  // (measured: +302 MiB and +602 MiB for a 300 MiB blob, +2 MiB bound).
  SqliteStatement& BindZeroBlob(int index, int64_t bytes);

  // Advances to the next row: true on a row, false when the statement is done.
  absl::StatusOr<bool> Step();
  // Runs a statement that returns no rows to completion.
  absl::Status Run();
  // Makes the statement runnable again and clears its bindings.
  void Reset();

  // Columns of the current row, counted from 0.
  int64_t ColumnInt64(int index) const;
  double ColumnDouble(int index) const;
  std::string ColumnText(int index) const;
  // Valid until the next Step(), Reset() or destruction.
  absl::string_view ColumnBlob(int index) const;

 private:
  explicit SqliteStatement(sqlite3_stmt* stmt) : stmt_(stmt) {}
  SqliteStatement& Check(int rc, int index);
  // The statement's SQL, shortened, to say which statement failed.
  std::string Context() const;

  sqlite3_stmt* stmt_ = nullptr;
  absl::Status bind_status_;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_SQLITE_STATEMENT_H_
