// What a Database holds: one writer connection, serialised by a mutex, and a pool of read-only
// connections. In WAL mode readers see the last commit and never wait for the writer, nor it for
// them. The files that implement the Database's operations run their SQL through Write and Read:
// database.cc (Open, and the counts), database_clips.cc, database_spaces.cc and
// database_labels.cc.
//
// Thread-safe.
#ifndef MOTIONDB_STORAGE_INTERNAL_DATABASE_IMPL_H_
#define MOTIONDB_STORAGE_INTERNAL_DATABASE_IMPL_H_

#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "absl/status/status.h"
#include "storage/database.h"
#include "storage/read_pool.h"
#include "storage/sqlite_connection.h"

namespace motiondb::storage {

class Database::Impl {
 public:
  // `writer`: an open read-write connection to `path`, its file prepared (schema and pragmas).
  Impl(const std::string& path, int busy_timeout_ms, std::unique_ptr<SqliteConnection> writer);

  // Runs `body` in one write transaction, committed when it succeeds and `write.should_stop`
  // does not say stop (CANCELLED), rolled back otherwise. UNAVAILABLE when another connection
  // holds the write lock past the busy timeout.
  absl::Status Write(const WriteOptions& write,
                     const std::function<absl::Status(SqliteConnection&)>& body);

  // Runs `body` on a read connection, in one snapshot.
  absl::Status Read(const std::function<absl::Status(SqliteConnection&)>& body);

 private:
  std::mutex write_mutex_;
  // Declared before the readers so that it closes last: the last connection to close
  // checkpoints the log into the database file and removes it. Used under write_mutex_.
  std::unique_ptr<SqliteConnection> writer_;
  ReadPool readers_;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_INTERNAL_DATABASE_IMPL_H_
