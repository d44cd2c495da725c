// Database::Backup: SQLite's online backup API, from a read connection.
#include <sqlite3.h>

#include <filesystem>
#include <memory>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "storage/database.h"
#include "storage/internal/database_impl.h"
#include "storage/sqlite_status.h"
#include "util/status_macros.h"

namespace motiondb::storage {

absl::Status Database::Backup(const std::string& path, const BackupOptions& options) {
  std::error_code error;
  if (std::filesystem::exists(path, error) && std::filesystem::file_size(path, error) != 0) {
    return absl::AlreadyExistsError(
        absl::StrCat("backup target ", path, " exists and is not empty; it was left untouched"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<SqliteConnection> target,
                            SqliteConnection::Open(path, SqliteConnection::Mode::kReadWriteCreate,
                                                   /*busy_timeout_ms=*/0));
  if (!options.durable) MOTIONDB_RETURN_IF_ERROR(target->Execute("PRAGMA synchronous = OFF"));
  const absl::Status copied = impl_->Read([&](SqliteConnection& source) -> absl::Status {
    sqlite3_backup* backup = sqlite3_backup_init(target->handle(), "main", source.handle(), "main");
    if (backup == nullptr) {
      return SqliteStatus(target->handle(), sqlite3_errcode(target->handle()), "backup");
    }
    // All pages in one step, so that the copy is of one snapshot: a backup made in several steps
    // restarts whenever another connection writes between them, which under steady ingest may
    // be forever. In WAL mode the snapshot blocks no writer.
    const int step = sqlite3_backup_step(backup, -1);
    const int finish = sqlite3_backup_finish(backup);
    if (step != SQLITE_DONE) return SqliteStatus(target->handle(), step, "backup");
    if (finish != SQLITE_OK) return SqliteStatus(target->handle(), finish, "backup");
    return absl::OkStatus();
  });
  target.reset();
  // No half copy is left to be mistaken for a backup.
  if (!copied.ok()) {
    std::filesystem::remove(path, error);
    std::filesystem::remove(path + "-journal", error);
  }
  return copied;
}

}  // namespace motiondb::storage
