// Read-only connections for concurrent readers. In WAL mode a reader sees the last committed
// state without taking locks that block the writer or other readers, so each read leases its
// own connection. Idle connections are kept (up to `max_idle`) to save reopening; a burst of
// readers opens more rather than waiting for one to come back.
//
// Thread-safe.
#ifndef MOTIONDB_STORAGE_READ_POOL_H_
#define MOTIONDB_STORAGE_READ_POOL_H_

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "storage/sqlite_connection.h"

namespace motiondb::storage {

class ReadPool {
 public:
  // A connection on loan; it returns to the pool when the lease is destroyed.
  class Lease {
   public:
    Lease(ReadPool* pool, std::unique_ptr<SqliteConnection> connection)
        : pool_(pool), connection_(std::move(connection)) {}
    Lease(Lease&&) = default;
    Lease& operator=(Lease&&) = delete;
    ~Lease() {
      if (connection_ != nullptr) pool_->Return(std::move(connection_));
    }
    SqliteConnection& operator*() const { return *connection_; }

   private:
    ReadPool* pool_;
    std::unique_ptr<SqliteConnection> connection_;
  };

  ReadPool(std::string path, int busy_timeout_ms, int max_idle)
      : path_(std::move(path)), busy_timeout_ms_(busy_timeout_ms), max_idle_(max_idle) {}
  // Every lease must have ended.
  ~ReadPool() = default;

  absl::StatusOr<Lease> Acquire();

 private:
  void Return(std::unique_ptr<SqliteConnection> connection);

  const std::string path_;
  const int busy_timeout_ms_;
  const size_t max_idle_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<SqliteConnection>> idle_;  // guarded by mutex_
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_READ_POOL_H_
