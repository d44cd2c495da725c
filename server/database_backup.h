// A consistent copy of the live database for a client to download (ServerService.CreateBackup):
// made aside in the database's folder with storage::Database::Backup, opened as a database to
// check it and count what it holds, then read back in chunks. The file is unlinked as soon as it
// is open, so a finished, failed or abandoned download leaves nothing behind; only a crash in
// the seconds between the copy and the unlink leaves a ".motiondb-backup-*" file.
//
// Not thread-safe: one call's.
#ifndef MOTIONDB_SERVER_DATABASE_BACKUP_H_
#define MOTIONDB_SERVER_DATABASE_BACKUP_H_

#include <cstdint>
#include <fstream>
#include <string>

#include "absl/status/statusor.h"
#include "storage/database.h"

namespace motiondb::server {

class DatabaseBackup {
 public:
  // `database_path`: the live database's file, beside which the copy is made (the same disk:
  // RESOURCE_EXHAUSTED when it lacks the room).
  static absl::StatusOr<DatabaseBackup> Create(storage::Database& database,
                                               const std::string& database_path);

  int64_t size_bytes() const { return size_bytes_; }
  const storage::Counts& counts() const { return counts_; }

  // The next up to `max_bytes` of the copy; empty once it has all been read.
  absl::StatusOr<std::string> ReadChunk(size_t max_bytes);

 private:
  DatabaseBackup(std::ifstream file, int64_t size_bytes, storage::Counts counts)
      : file_(std::move(file)), size_bytes_(size_bytes), counts_(counts) {}

  std::ifstream file_;
  int64_t size_bytes_;
  int64_t read_bytes_ = 0;
  storage::Counts counts_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_DATABASE_BACKUP_H_
