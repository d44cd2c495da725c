#include "server/database_backup.h"

#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <system_error>
#include <utility>

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// A new empty file beside `database_path`, for the copy.
absl::StatusOr<std::string> MakeTargetFile(const std::string& database_path) {
  std::filesystem::path folder = std::filesystem::path(database_path).parent_path();
  if (folder.empty()) folder = ".";
  std::string name = (folder / ".motiondb-backup-XXXXXX").string();
  const int fd = ::mkstemp(name.data());
  if (fd < 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot create the backup file in ", folder.string()));
  }
  ::close(fd);
  return name;
}

void RemoveCopy(const std::string& path) {
  std::error_code ignored;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
    std::filesystem::remove(path + suffix, ignored);
  }
}

// Opens the copy as motiondb does (schema version, quick_check) and counts what it holds.
absl::StatusOr<storage::Counts> CheckCopy(const std::string& path) {
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> copy,
                            storage::Database::Open(path, {.create_if_missing = false}));
  return copy->GetCounts();
}

}  // namespace

absl::StatusOr<DatabaseBackup> DatabaseBackup::Create(storage::Database& database,
                                                      const std::string& database_path) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string path, MakeTargetFile(database_path));
  absl::Status copied = database.Backup(path, {.durable = false});
  absl::StatusOr<storage::Counts> counts =
      copied.ok() ? CheckCopy(path) : absl::StatusOr<storage::Counts>(copied);
  std::ifstream file;
  if (counts.ok()) file.open(path, std::ios::binary);
  std::error_code error;
  const auto size = static_cast<int64_t>(std::filesystem::file_size(path, error));
  // Open (or failed): the name is no longer needed.
  RemoveCopy(path);
  MOTIONDB_RETURN_IF_ERROR(counts.status());
  if (!file || error) return absl::InternalError("the backup copy could not be read back");
  return DatabaseBackup(std::move(file), size, *counts);
}

absl::StatusOr<std::string> DatabaseBackup::ReadChunk(size_t max_bytes) {
  std::string chunk(std::min<int64_t>(max_bytes, size_bytes_ - read_bytes_), '\0');
  if (chunk.empty()) return chunk;
  if (!file_.read(chunk.data(), static_cast<std::streamsize>(chunk.size()))) {
    return absl::InternalError(
        absl::StrCat("the backup copy could not be read at byte ", read_bytes_));
  }
  read_bytes_ += static_cast<int64_t>(chunk.size());
  return chunk;
}

}  // namespace motiondb::server
