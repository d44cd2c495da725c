#include "storage/read_pool.h"

#include <utility>

#include "util/status_macros.h"

namespace motiondb::storage {

absl::StatusOr<ReadPool::Lease> ReadPool::Acquire() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!idle_.empty()) {
      std::unique_ptr<SqliteConnection> connection = std::move(idle_.back());
      idle_.pop_back();
      return Lease(this, std::move(connection));
    }
  }
  // Opened outside the lock: opening touches the file system.
  MOTIONDB_ASSIGN_OR_RETURN(
      std::unique_ptr<SqliteConnection> connection,
      SqliteConnection::Open(path_, SqliteConnection::Mode::kReadOnly, busy_timeout_ms_));
  return Lease(this, std::move(connection));
}

void ReadPool::Return(std::unique_ptr<SqliteConnection> connection) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (idle_.size() < max_idle_) idle_.push_back(std::move(connection));
  // Otherwise it closes here; closing a read-only connection is cheap.
}

}  // namespace motiondb::storage
