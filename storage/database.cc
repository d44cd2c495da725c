#include "storage/database.h"

#include <filesystem>
#include <fstream>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_rows.h"
#include "storage/schema.h"
#include "storage/sqlite_transaction.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::storage {
namespace {

// Read connections kept open between reads; more are opened while more threads read at once.
constexpr int kMaxIdleReaders = 8;

// Refuses, without writing a byte, a non-empty file that is not SQLite: SQLite itself would
// only notice at the first read, and an empty file is how SQLite starts a new database anyway.
absl::Status CheckSqliteHeader(const std::string& path) {
  constexpr absl::string_view kHeader("SQLite format 3\0", 16);
  std::ifstream file(path, std::ios::binary);
  if (!file) return absl::FailedPreconditionError("the file cannot be read");
  char header[16] = {};
  file.read(header, sizeof(header));
  if (file.gcount() == 0) return absl::OkStatus();
  if (absl::string_view(header, file.gcount()) != kHeader) {
    return absl::FailedPreconditionError(
        "the file is not a SQLite database (its first bytes are not the SQLite header); it was "
        "left untouched");
  }
  return absl::OkStatus();
}

absl::Status QuickCheck(SqliteConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement check, connection.Prepare("PRAGMA quick_check(5)"));
  std::vector<std::string> problems;
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, check.Step());
    if (!row) break;
    // A row can hold several lines ("*** in database main ***" and the pages at fault).
    problems.push_back(absl::StrReplaceAll(check.ColumnText(0), {{"\n", "; "}}));
  }
  if (problems.size() == 1 && problems[0] == "ok") return absl::OkStatus();
  return absl::FailedPreconditionError(absl::StrCat(
      "the file failed its integrity check (PRAGMA quick_check): ", absl::StrJoin(problems, "; ")));
}

// A job found queued or running at open was cut off: its process ended (stopped, crashed or
// killed) without finishing it, since one process serves a file at a time. Its output, written
// in the transaction that ends a job, is absent, so the job can simply be started again.
absl::Status InterruptUnfinishedJobs(SqliteConnection& writer) {
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement update,
      writer.Prepare("UPDATE jobs SET state = 'interrupted', finished_unix_ms = ?, error = "
                     "'the server stopped before the job ended' WHERE state IN ('queued', "
                     "'running')"));
  return update.BindInt64(1, CreationTime(0)).Run();
}

// Migrates `writer`'s file under a rollback journal when it has migrations to run: in WAL mode
// every page a table's rewrite reads back is looked up in a log holding every page it wrote,
// which grows with the rewrite (measured on a 714 MB file at schema 4: served after 67 s in WAL
// mode, 38-46 s under a rollback journal). Best effort: while another process reads the file,
// SQLite refuses the switch ("database is locked" once the busy timeout passes), and the file
// migrates in WAL mode, as correctly.
absl::Status MigrateUnderRollbackJournal(SqliteConnection& writer) {
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t version, writer.QueryInt64("PRAGMA user_version"));
  if (version < LatestSchemaVersion()) {
    writer.QueryText("PRAGMA journal_mode = DELETE").status().IgnoreError();
  }
  return MigrateSchema(writer);
}

// Everything Open does on the writer connection once the file is known to be SQLite.
absl::Status PrepareFile(SqliteConnection& writer, const DatabaseOptions& options) {
  // Read-only checks first, so that a file this build must refuse is not modified.
  MOTIONDB_RETURN_IF_ERROR(CheckSchemaVersion(writer));
  if (options.integrity_check) MOTIONDB_RETURN_IF_ERROR(QuickCheck(writer));
  // synchronous=FULL: in WAL mode, NORMAL may lose the last commits on power loss; FULL syncs
  // the log at every commit, so an acknowledged write survives. journal_size_limit: the log is
  // cut back to 64 MiB once checkpointed, rather than kept at the size of the largest
  // transaction ever written (a large clip's ingest, a migration).
  MOTIONDB_RETURN_IF_ERROR(writer.Execute(
      "PRAGMA foreign_keys = ON; PRAGMA synchronous = FULL; PRAGMA journal_size_limit = 67108864"));
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t foreign_keys, writer.QueryInt64("PRAGMA foreign_keys"));
  if (foreign_keys != 1) {
    return absl::FailedPreconditionError("this SQLite build does not enforce foreign keys");
  }
  MOTIONDB_RETURN_IF_ERROR(MigrateUnderRollbackJournal(writer));
  MOTIONDB_ASSIGN_OR_RETURN(const std::string journal,
                            writer.QueryText("PRAGMA journal_mode = WAL"));
  if (absl::AsciiStrToLower(journal) != "wal") {
    return absl::FailedPreconditionError(
        absl::StrCat("the file cannot use write-ahead logging (journal mode is ", journal, ")"));
  }
  return InterruptUnfinishedJobs(writer);
}

// The writer connection of a file, checked and prepared; errors do not name the file.
absl::StatusOr<std::unique_ptr<SqliteConnection>> OpenWriter(const std::string& path,
                                                             const DatabaseOptions& options) {
  std::error_code error;
  const bool exists = std::filesystem::exists(path, error);
  if (!exists && !options.create_if_missing) return absl::NotFoundError("no such file");
  if (exists) MOTIONDB_RETURN_IF_ERROR(CheckSqliteHeader(path));
  MOTIONDB_ASSIGN_OR_RETURN(
      std::unique_ptr<SqliteConnection> writer,
      SqliteConnection::Open(path,
                             options.create_if_missing ? SqliteConnection::Mode::kReadWriteCreate
                                                       : SqliteConnection::Mode::kReadWrite,
                             options.busy_timeout_ms));
  if (absl::Status status = PrepareFile(*writer, options); !status.ok()) {
    // A damaged file is a precondition of Open, not a loss Open caused.
    if (absl::IsDataLoss(status)) {
      return absl::FailedPreconditionError(absl::StrCat("the file is damaged: ", status.message()));
    }
    return status;
  }
  return writer;
}

}  // namespace

Database::Impl::Impl(const std::string& path, int busy_timeout_ms,
                     std::unique_ptr<SqliteConnection> writer)
    : writer_(std::move(writer)), readers_(path, busy_timeout_ms, kMaxIdleReaders) {}

absl::Status Database::Impl::Write(const WriteOptions& write,
                                   const std::function<absl::Status(SqliteConnection&)>& body) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  absl::StatusOr<SqliteTransaction> transaction =
      SqliteTransaction::Begin(*writer_, SqliteTransaction::Kind::kWrite);
  if (absl::IsUnavailable(transaction.status())) {
    // This Database has one writer: the lock is another process's (or another Database's).
    return Prefixed("another connection held the write lock for longer than the busy timeout",
                    transaction.status());
  }
  if (!transaction.ok()) return transaction.status();
  MOTIONDB_RETURN_IF_ERROR(body(*writer_));
  // Asked as late as possible: the call may end while the write waited for the lock or ran.
  if (write.should_stop && write.should_stop()) {
    return absl::CancelledError("the call ended before the write committed; nothing was written");
  }
  return transaction->Commit();
}

absl::Status Database::Impl::Read(const std::function<absl::Status(SqliteConnection&)>& body) {
  MOTIONDB_ASSIGN_OR_RETURN(ReadPool::Lease lease, readers_.Acquire());
  MOTIONDB_ASSIGN_OR_RETURN(SqliteTransaction transaction,
                            SqliteTransaction::Begin(*lease, SqliteTransaction::Kind::kRead));
  MOTIONDB_RETURN_IF_ERROR(body(*lease));
  return transaction.Commit();
}

Database::Database(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Database::~Database() = default;

absl::StatusOr<std::unique_ptr<Database>> Database::Open(const std::string& path,
                                                         const DatabaseOptions& options) {
  // Readers open their own connections to the same file, which an in-memory database is not.
  if (path.empty() || path == ":memory:") {
    return absl::InvalidArgumentError("the database needs a file path (not in-memory)");
  }
  if (options.busy_timeout_ms < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("busy_timeout_ms must not be negative, got ", options.busy_timeout_ms));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      std::unique_ptr<SqliteConnection> writer,
      Prefixed(absl::StrCat("database '", path, "'"), OpenWriter(path, options)));
  return std::unique_ptr<Database>(
      new Database(std::make_unique<Impl>(path, options.busy_timeout_ms, std::move(writer))));
}

absl::StatusOr<Counts> Database::GetCounts() {
  Counts counts;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare("SELECT (SELECT count(*) FROM skeletons), (SELECT count(*) FROM clips), "
                   "(SELECT coalesce(sum(frame_count), 0) FROM clips), "
                   "(SELECT count(*) FROM spaces), (SELECT count(*) FROM projections), "
                   "(SELECT count(*) FROM labels)"));
    MOTIONDB_RETURN_IF_ERROR(query.Step().status());
    counts.skeletons = query.ColumnInt64(0);
    counts.clips = query.ColumnInt64(1);
    counts.frames = query.ColumnInt64(2);
    counts.spaces = query.ColumnInt64(3);
    counts.projections = query.ColumnInt64(4);
    counts.labels = query.ColumnInt64(5);
    return absl::OkStatus();
  }));
  return counts;
}

}  // namespace motiondb::storage
