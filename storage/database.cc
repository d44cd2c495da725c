#include "storage/database.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "core/space/space_serialization.h"
#include "storage/blob_codec.h"
#include "storage/read_pool.h"
#include "storage/schema.h"
#include "storage/sqlite_connection.h"
#include "storage/sqlite_transaction.h"
#include "util/status_macros.h"

namespace motiondb::storage {
namespace {

constexpr size_t kMaxNameBytes = 512;
constexpr size_t kMaxTagBytes = 128;
constexpr size_t kMaxTags = 64;
constexpr int kDefaultPageSize = 100;
constexpr int kMaxPageSize = 1000;
// Read connections kept open between reads; more are opened while more threads read at once.
constexpr int kMaxIdleReaders = 8;

// Column lists shared by the statements that fill records (ReadClipRecord, ReadSpaceRecord).
constexpr absl::string_view kClipRecordColumns =
    "c.clip_id, c.name, c.source_file, c.skeleton_id, c.created_unix_ms, c.frame_time, "
    "c.frame_count, c.joint_count";
constexpr absl::string_view kSpaceRecordColumns =
    "space_id, name, skeleton_id, version, created_unix_ms, build_report_json";

// A record's creation time: as given, or now when it is 0.
int64_t CreationTime(int64_t given_unix_ms) {
  if (given_unix_ms > 0) return given_unix_ms;
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

absl::Status CheckName(absl::string_view what, absl::string_view name, size_t max_bytes,
                       bool may_be_empty = false) {
  if (name.empty() && !may_be_empty) {
    return absl::InvalidArgumentError(absl::StrCat(what, " must not be empty"));
  }
  if (name.size() > max_bytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, " is ", name.size(), " bytes long, at most ", max_bytes, " are allowed"));
  }
  return absl::OkStatus();
}

// Tags are a set: checked, sorted and without repeats, as ListClips and GetClip return them.
absl::StatusOr<std::vector<std::string>> CanonicalTags(std::vector<std::string> tags) {
  if (tags.size() > kMaxTags) {
    return absl::InvalidArgumentError(
        absl::StrCat("a clip has at most ", kMaxTags, " tags, got ", tags.size()));
  }
  for (const std::string& tag : tags) MOTIONDB_RETURN_IF_ERROR(CheckName("tag", tag, kMaxTagBytes));
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
  return tags;
}

// `space_dims`: the dimensions of the stored space, when known yet.
absl::Status CheckProjection(const RowMatrixXf& coordinates, std::optional<int> space_dims,
                             absl::string_view what) {
  if (coordinates.cols() < 1)
    return absl::InvalidArgumentError(absl::StrCat(what, " has no columns"));
  if (space_dims && coordinates.cols() > *space_dims) {
    return absl::InvalidArgumentError(absl::StrCat(what, " has ", coordinates.cols(),
                                                   " columns, more than the space's ", *space_dims,
                                                   " dimensions"));
  }
  if (!coordinates.allFinite()) {
    return absl::InvalidArgumentError(absl::StrCat(what, " contains NaN or infinite values"));
  }
  return absl::OkStatus();
}

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

// Everything Open does on the writer connection once the file is known to be SQLite.
absl::Status PrepareFile(SqliteConnection& writer, const DatabaseOptions& options) {
  // Read-only checks first, so that a file this build must refuse is not modified.
  MOTIONDB_RETURN_IF_ERROR(CheckSchemaVersion(writer));
  if (options.integrity_check) MOTIONDB_RETURN_IF_ERROR(QuickCheck(writer));
  MOTIONDB_ASSIGN_OR_RETURN(const std::string journal,
                            writer.QueryText("PRAGMA journal_mode = WAL"));
  if (absl::AsciiStrToLower(journal) != "wal") {
    return absl::FailedPreconditionError(
        absl::StrCat("the file cannot use write-ahead logging (journal mode is ", journal, ")"));
  }
  // In WAL mode, synchronous=NORMAL may lose the last commits on power loss; FULL syncs the
  // log at every commit, so an acknowledged write survives.
  MOTIONDB_RETURN_IF_ERROR(writer.Execute("PRAGMA foreign_keys = ON; PRAGMA synchronous = FULL"));
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t foreign_keys, writer.QueryInt64("PRAGMA foreign_keys"));
  if (foreign_keys != 1) {
    return absl::FailedPreconditionError("this SQLite build does not enforce foreign keys");
  }
  return MigrateSchema(writer);
}

// Columns as kClipRecordColumns lists them, from `first`; tags are added separately.
ClipRecord ReadClipRecord(const SqliteStatement& row, int first = 0) {
  ClipRecord record;
  record.clip_id = row.ColumnInt64(first);
  record.name = row.ColumnText(first + 1);
  record.source_file = row.ColumnText(first + 2);
  record.skeleton_id = row.ColumnInt64(first + 3);
  record.created_unix_ms = row.ColumnInt64(first + 4);
  record.frame_time = row.ColumnDouble(first + 5);
  record.frame_count = row.ColumnInt64(first + 6);
  record.joint_count = static_cast<int>(row.ColumnInt64(first + 7));
  return record;
}

SpaceRecord ReadSpaceRecord(const SqliteStatement& row) {
  SpaceRecord record;
  record.space_id = row.ColumnInt64(0);
  record.name = row.ColumnText(1);
  record.skeleton_id = row.ColumnInt64(2);
  record.version = static_cast<int>(row.ColumnInt64(3));
  record.created_unix_ms = row.ColumnInt64(4);
  record.build_report_json = row.ColumnText(5);
  return record;
}

// Reads the tags of one clip with `tags`, a prepared "SELECT tag ... WHERE clip_id = ?"
// reused for every clip of a page.
absl::StatusOr<std::vector<std::string>> LoadTags(SqliteStatement& tags, int64_t clip_id) {
  tags.Reset();
  tags.BindInt64(1, clip_id);
  std::vector<std::string> result;
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, tags.Step());
    if (!row) return result;
    result.push_back(tags.ColumnText(0));
  }
}

absl::StatusOr<SqliteStatement> PrepareTagQuery(SqliteConnection& db) {
  return db.Prepare("SELECT tag FROM clip_tags WHERE clip_id = ? ORDER BY tag");
}

// Whether `sql`, with its one parameter bound to `key`, returns a row.
absl::StatusOr<bool> Exists(SqliteConnection& db, absl::string_view sql, int64_t key) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query, db.Prepare(sql));
  return query.BindInt64(1, key).Step();
}

// ALREADY_EXISTS when `table` ("clips" or "spaces") has a row called `name`.
absl::Status CheckNameFree(SqliteConnection& db, absl::string_view table, absl::string_view what,
                           absl::string_view name) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                            db.Prepare(absl::StrCat("SELECT 1 FROM ", table, " WHERE name = ?")));
  MOTIONDB_ASSIGN_OR_RETURN(const bool taken, query.BindText(1, name).Step());
  if (taken) {
    return absl::AlreadyExistsError(absl::StrCat("a ", what, " named '", name, "' already exists"));
  }
  return absl::OkStatus();
}

absl::StatusOr<int64_t> FindOrCreateSkeleton(SqliteConnection& db, const Skeleton& skeleton,
                                             const std::string& key, int64_t now) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement find,
                            db.Prepare("SELECT skeleton_id FROM skeletons WHERE topology_key = ?"));
  MOTIONDB_ASSIGN_OR_RETURN(const bool found, find.BindText(1, key).Step());
  if (found) return find.ColumnInt64(0);
  std::vector<std::string> names;
  std::vector<int> parents;
  for (const Joint& joint : skeleton.joints()) {
    names.push_back(joint.name);
    parents.push_back(joint.parent);
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement insert,
      db.Prepare("INSERT INTO skeletons (topology_key, joint_count, joint_names, joint_parents, "
                 "created_unix_ms) VALUES (?, ?, ?, ?, ?)"));
  MOTIONDB_RETURN_IF_ERROR(insert.BindText(1, key)
                               .BindInt64(2, skeleton.joint_count())
                               .BindText(3, absl::StrJoin(names, "\n"))
                               .BindText(4, absl::StrJoin(parents, ","))
                               .BindInt64(5, now)
                               .Run());
  return sqlite3_last_insert_rowid(db.handle());
}

absl::StatusOr<SqliteStatement> PrepareProjectionInsert(SqliteConnection& db) {
  return db.Prepare(
      "INSERT INTO projections (space_id, clip_id, frames, dims, data) VALUES (?, ?, ?, ?, ?)");
}

absl::Status InsertProjection(SqliteStatement& insert, int64_t space_id, int64_t clip_id,
                              const RowMatrixXf& coordinates) {
  const std::string data = Float32Blob(coordinates);
  insert.Reset();
  return insert.BindInt64(1, space_id)
      .BindInt64(2, clip_id)
      .BindInt64(3, coordinates.rows())
      .BindInt64(4, coordinates.cols())
      .BindBlob(5, data)
      .Run();
}

// Runs `erase`, a bound DELETE of one row (its foreign keys cascade); NOT_FOUND with `missing`
// when there was no such row.
absl::Status DeleteRow(SqliteConnection& db, SqliteStatement& erase, absl::string_view missing) {
  MOTIONDB_RETURN_IF_ERROR(erase.Run());
  if (sqlite3_changes(db.handle()) == 0) return absl::NotFoundError(missing);
  return absl::OkStatus();
}

// `status` with `prefix` in front of its message.
absl::Status Annotate(const absl::Status& status, absl::string_view prefix) {
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

}  // namespace

// One writer connection, serialised by a mutex, and a pool of read-only connections. In WAL
// mode readers see the last commit and never wait for the writer, nor it for them.
class Database::Impl {
 public:
  Impl(const std::string& path, int busy_timeout_ms, std::unique_ptr<SqliteConnection> writer)
      : writer_(std::move(writer)), readers_(path, busy_timeout_ms, kMaxIdleReaders) {}

  // Runs `body` in one write transaction, committed when it succeeds and rolled back otherwise.
  absl::Status Write(const std::function<absl::Status(SqliteConnection&)>& body) {
    std::lock_guard<std::mutex> lock(write_mutex_);
    absl::StatusOr<SqliteTransaction> transaction =
        SqliteTransaction::Begin(*writer_, SqliteTransaction::Kind::kWrite);
    if (absl::IsUnavailable(transaction.status())) {
      // This Database has one writer: the lock is another process's (or another Database's).
      return Annotate(transaction.status(),
                      "another connection held the write lock for longer than the busy timeout; ");
    }
    if (!transaction.ok()) return transaction.status();
    MOTIONDB_RETURN_IF_ERROR(body(*writer_));
    return transaction->Commit();
  }

  // Runs `body` on a read connection, in one snapshot.
  absl::Status Read(const std::function<absl::Status(SqliteConnection&)>& body) {
    MOTIONDB_ASSIGN_OR_RETURN(ReadPool::Lease lease, readers_.Acquire());
    MOTIONDB_ASSIGN_OR_RETURN(SqliteTransaction transaction,
                              SqliteTransaction::Begin(*lease, SqliteTransaction::Kind::kRead));
    MOTIONDB_RETURN_IF_ERROR(body(*lease));
    return transaction.Commit();
  }

 private:
  std::mutex write_mutex_;
  // Declared before the readers so that it closes last: the last connection to close
  // checkpoints the log into the database file and removes it.
  std::unique_ptr<SqliteConnection> writer_;
  ReadPool readers_;
};

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
  const std::string prefix = absl::StrCat("database '", path, "': ");
  std::error_code error;
  const bool exists = std::filesystem::exists(path, error);
  if (!exists && !options.create_if_missing) {
    return absl::NotFoundError(absl::StrCat(prefix, "no such file"));
  }
  if (exists) {
    if (absl::Status status = CheckSqliteHeader(path); !status.ok()) {
      return Annotate(status, prefix);
    }
  }
  absl::StatusOr<std::unique_ptr<SqliteConnection>> writer =
      SqliteConnection::Open(path,
                             options.create_if_missing ? SqliteConnection::Mode::kReadWriteCreate
                                                       : SqliteConnection::Mode::kReadWrite,
                             options.busy_timeout_ms);
  if (!writer.ok()) return Annotate(writer.status(), prefix);
  if (absl::Status status = PrepareFile(**writer, options); !status.ok()) {
    // A damaged file is a precondition of Open, not a loss Open caused.
    if (absl::IsDataLoss(status)) {
      return absl::FailedPreconditionError(
          absl::StrCat(prefix, "the file is damaged: ", status.message()));
    }
    return Annotate(status, prefix);
  }
  return std::unique_ptr<Database>(
      new Database(std::make_unique<Impl>(path, options.busy_timeout_ms, *std::move(writer))));
}

absl::StatusOr<int64_t> Database::InsertClip(
    const ClipRecord& record, const Clip& clip,
    const std::vector<std::pair<int64_t, Projection>>& projections) {
  MOTIONDB_RETURN_IF_ERROR(CheckName("clip name", record.name, kMaxNameBytes));
  MOTIONDB_RETURN_IF_ERROR(
      CheckName("source file name", record.source_file, kMaxNameBytes, /*may_be_empty=*/true));
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<std::string> tags, CanonicalTags(record.tags));
  MOTIONDB_RETURN_IF_ERROR(CheckFloat32Range(clip.positions(), "clip position"));
  absl::flat_hash_set<int64_t> space_ids;
  for (const auto& [space_id, projection] : projections) {
    if (!space_ids.insert(space_id).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("two projections of the clip into space ", space_id));
    }
    // The dimensions are checked against the stored space below.
    MOTIONDB_RETURN_IF_ERROR(CheckProjection(projection.coordinates, std::nullopt,
                                             absl::StrCat("projection into space ", space_id)));
  }
  // Encoded before the write lock, which other writers wait for.
  const std::string key = TopologyKey(clip.skeleton());
  const std::string layout = SkeletonLayoutBlob(clip.skeleton());
  const std::string rotations = Float32Blob(clip.rotations());
  const std::string positions = Float32Blob(clip.positions());
  const int64_t now = CreationTime(record.created_unix_ms);

  int64_t clip_id = 0;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_RETURN_IF_ERROR(CheckNameFree(db, "clips", "clip", record.name));
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t skeleton_id,
                              FindOrCreateSkeleton(db, clip.skeleton(), key, now));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO clips (name, source_file, skeleton_id, frame_time, frame_count, "
                   "joint_count, position_joint_count, layout, rotations, positions, "
                   "created_unix_ms) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"));
    MOTIONDB_RETURN_IF_ERROR(insert.BindText(1, record.name)
                                 .BindText(2, record.source_file)
                                 .BindInt64(3, skeleton_id)
                                 .BindDouble(4, clip.frame_time())
                                 .BindInt64(5, clip.frame_count())
                                 .BindInt64(6, clip.skeleton().joint_count())
                                 .BindInt64(7, clip.skeleton().position_joint_count())
                                 .BindBlob(8, layout)
                                 .BindBlob(9, rotations)
                                 .BindBlob(10, positions)
                                 .BindInt64(11, now)
                                 .Run());
    clip_id = sqlite3_last_insert_rowid(db.handle());

    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement insert_tag,
                              db.Prepare("INSERT INTO clip_tags (clip_id, tag) VALUES (?, ?)"));
    for (const std::string& tag : tags) {
      insert_tag.Reset();
      MOTIONDB_RETURN_IF_ERROR(insert_tag.BindInt64(1, clip_id).BindText(2, tag).Run());
    }

    // The spaces of this skeleton, each of which must receive the clip's projection.
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement spaces,
        db.Prepare("SELECT space_id, name, dims FROM spaces WHERE skeleton_id = ?"));
    spaces.BindInt64(1, skeleton_id);
    absl::flat_hash_map<int64_t, std::pair<std::string, int>> needed;
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, spaces.Step());
      if (!row) break;
      needed[spaces.ColumnInt64(0)] = {spaces.ColumnText(1),
                                       static_cast<int>(spaces.ColumnInt64(2))};
    }
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement insert_projection, PrepareProjectionInsert(db));
    for (const auto& [space_id, projection] : projections) {
      const auto space = needed.find(space_id);
      if (space == needed.end()) {
        MOTIONDB_ASSIGN_OR_RETURN(const bool exists,
                                  Exists(db, "SELECT 1 FROM spaces WHERE space_id = ?", space_id));
        if (!exists) return absl::NotFoundError(absl::StrCat("space ", space_id, " not found"));
        return absl::FailedPreconditionError(
            absl::StrCat("space ", space_id, " belongs to another skeleton than the clip's"));
      }
      MOTIONDB_RETURN_IF_ERROR(CheckProjection(projection.coordinates, space->second.second,
                                               absl::StrCat("projection into space ", space_id)));
      MOTIONDB_RETURN_IF_ERROR(
          InsertProjection(insert_projection, space_id, clip_id, projection.coordinates));
      needed.erase(space);
    }
    if (!needed.empty()) {
      const auto& [space_id, space] = *needed.begin();
      return absl::FailedPreconditionError(absl::StrCat(
          "the clip has no projection into space ", space_id, " ('", space.first,
          "') of its skeleton; a clip is stored with its projection into every such space"));
    }
    return absl::OkStatus();
  }));
  return clip_id;
}

absl::StatusOr<int64_t> Database::FindSkeleton(const Skeleton& skeleton) {
  const std::string key = TopologyKey(skeleton);
  int64_t skeleton_id = -1;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement find,
        db.Prepare("SELECT skeleton_id FROM skeletons WHERE topology_key = ?"));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, find.BindText(1, key).Step());
    if (found) skeleton_id = find.ColumnInt64(0);
    return absl::OkStatus();
  }));
  return skeleton_id;
}

absl::StatusOr<StoredClip> Database::GetClip(int64_t clip_id) {
  std::optional<StoredClip> result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(absl::StrCat("SELECT ", kClipRecordColumns,
                                ", c.position_joint_count, c.layout, c.rotations, c.positions "
                                "FROM clips c WHERE c.clip_id = ?")));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindInt64(1, clip_id).Step());
    if (!found) return absl::NotFoundError(absl::StrCat("clip ", clip_id, " not found"));
    const std::string context = absl::StrCat("stored clip ", clip_id, ": ");
    ClipRecord record = ReadClipRecord(query);
    const double frame_time = record.frame_time;
    const int64_t frames = record.frame_count;
    const int64_t joints = record.joint_count;
    const int64_t position_joints = query.ColumnInt64(8);
    absl::StatusOr<std::shared_ptr<const Skeleton>> skeleton =
        ParseSkeletonLayout(query.ColumnBlob(9));
    if (!skeleton.ok())
      return absl::DataLossError(absl::StrCat(context, skeleton.status().message()));
    if ((*skeleton)->joint_count() != joints ||
        (*skeleton)->position_joint_count() != position_joints) {
      return absl::DataLossError(absl::StrCat(context, "its layout does not match its row"));
    }
    absl::StatusOr<RowMatrixXd> rotations = ParseRotationBlob(query.ColumnBlob(10), frames, joints);
    if (!rotations.ok()) return Annotate(rotations.status(), context);
    absl::StatusOr<RowMatrixXf> positions =
        ParseFloat32Blob(query.ColumnBlob(11), frames, 3 * position_joints, "positions");
    if (!positions.ok()) return Annotate(positions.status(), context);
    absl::StatusOr<Clip> clip = Clip::Create(*std::move(skeleton), frame_time,
                                             *std::move(rotations), positions->cast<double>());
    if (!clip.ok()) return absl::DataLossError(absl::StrCat(context, clip.status().message()));
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement tags, PrepareTagQuery(db));
    MOTIONDB_ASSIGN_OR_RETURN(record.tags, LoadTags(tags, clip_id));
    result.emplace(StoredClip{std::move(record), *std::move(clip)});
    return absl::OkStatus();
  }));
  return *std::move(result);
}

absl::StatusOr<ClipRecord> Database::GetClipRecord(int64_t clip_id) {
  ClipRecord record;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              db.Prepare(absl::StrCat("SELECT ", kClipRecordColumns,
                                                      " FROM clips c WHERE c.clip_id = ?")));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindInt64(1, clip_id).Step());
    if (!found) return absl::NotFoundError(absl::StrCat("clip ", clip_id, " not found"));
    record = ReadClipRecord(query);
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement tags, PrepareTagQuery(db));
    MOTIONDB_ASSIGN_OR_RETURN(record.tags, LoadTags(tags, clip_id));
    return absl::OkStatus();
  }));
  return record;
}

absl::StatusOr<ClipPage> Database::ListClips(const Page& page, const std::string& tag) {
  const int page_size = page.page_size == 0 ? kDefaultPageSize : page.page_size;
  if (page_size < 1 || page_size > kMaxPageSize) {
    return absl::InvalidArgumentError(absl::StrCat("page_size must be 1 to ", kMaxPageSize,
                                                   " (0 for ", kDefaultPageSize, "), got ",
                                                   page.page_size));
  }
  // The token is the last clip id of the previous page, in decimal.
  int64_t after = 0;
  if (!page.page_token.empty()) {
    const bool digits = std::all_of(page.page_token.begin(), page.page_token.end(),
                                    [](char c) { return absl::ascii_isdigit(c); });
    if (!digits || !absl::SimpleAtoi(page.page_token, &after) || after <= 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("malformed page_token '", page.page_token.substr(0, 40), "'"));
    }
  }
  if (!tag.empty()) MOTIONDB_RETURN_IF_ERROR(CheckName("tag", tag, kMaxTagBytes));

  ClipPage result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    const std::string sql =
        tag.empty()
            ? absl::StrCat("SELECT ", kClipRecordColumns,
                           " FROM clips c WHERE c.clip_id > ?1 ORDER BY c.clip_id LIMIT ?2")
            : absl::StrCat("SELECT ", kClipRecordColumns,
                           " FROM clip_tags t JOIN clips c ON c.clip_id = t.clip_id "
                           "WHERE t.tag = ?3 AND t.clip_id > ?1 ORDER BY t.clip_id LIMIT ?2");
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query, db.Prepare(sql));
    // One row more than the page says whether another page follows.
    query.BindInt64(1, after).BindInt64(2, page_size + 1);
    if (!tag.empty()) query.BindText(3, tag);
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement tags, PrepareTagQuery(db));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) break;
      if (static_cast<int>(result.clips.size()) == page_size) {
        result.next_page_token = absl::StrCat(result.clips.back().clip_id);
        break;
      }
      ClipRecord record = ReadClipRecord(query);
      MOTIONDB_ASSIGN_OR_RETURN(record.tags, LoadTags(tags, record.clip_id));
      result.clips.push_back(std::move(record));
    }
    return absl::OkStatus();
  }));
  return result;
}

absl::Status Database::DeleteClip(int64_t clip_id) {
  return impl_->Write([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement erase,
                              db.Prepare("DELETE FROM clips WHERE clip_id = ?"));
    erase.BindInt64(1, clip_id);
    return DeleteRow(db, erase, absl::StrCat("clip ", clip_id, " not found"));
  });
}

absl::StatusOr<int64_t> Database::InsertSpace(const SpaceRecord& record, const MotionSpace& space,
                                              const std::vector<Projection>& projections) {
  MOTIONDB_RETURN_IF_ERROR(CheckName("space name", record.name, kMaxNameBytes));
  if (record.version < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("space version must be at least 1, got ", record.version));
  }
  absl::flat_hash_set<int64_t> clip_ids;
  for (const Projection& projection : projections) {
    if (!clip_ids.insert(projection.clip_id).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("two projections of clip ", projection.clip_id));
    }
    MOTIONDB_RETURN_IF_ERROR(
        CheckProjection(projection.coordinates, space.dims(),
                        absl::StrCat("projection of clip ", projection.clip_id)));
  }
  const std::string key = TopologyKey(space.skeleton());
  const std::string data = SerializeSpace(space);
  const int64_t now = CreationTime(record.created_unix_ms);

  int64_t space_id = 0;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_RETURN_IF_ERROR(CheckNameFree(db, "spaces", "space", record.name));
    int64_t skeleton_id = record.skeleton_id;
    if (skeleton_id == 0) {
      MOTIONDB_ASSIGN_OR_RETURN(skeleton_id, FindOrCreateSkeleton(db, space.skeleton(), key, now));
    } else {
      MOTIONDB_ASSIGN_OR_RETURN(
          SqliteStatement find,
          db.Prepare("SELECT topology_key FROM skeletons WHERE skeleton_id = ?"));
      MOTIONDB_ASSIGN_OR_RETURN(const bool found, find.BindInt64(1, skeleton_id).Step());
      if (!found) return absl::NotFoundError(absl::StrCat("skeleton ", skeleton_id, " not found"));
      if (find.ColumnText(0) != key) {
        return absl::FailedPreconditionError(
            absl::StrCat("the space's skeleton differs from skeleton ", skeleton_id,
                         " in joint names or parents"));
      }
    }
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO spaces (name, skeleton_id, version, dims, created_unix_ms, data, "
                   "build_report_json) VALUES (?, ?, ?, ?, ?, ?, ?)"));
    MOTIONDB_RETURN_IF_ERROR(insert.BindText(1, record.name)
                                 .BindInt64(2, skeleton_id)
                                 .BindInt64(3, record.version)
                                 .BindInt64(4, space.dims())
                                 .BindInt64(5, now)
                                 .BindBlob(6, data)
                                 .BindText(7, record.build_report_json)
                                 .Run());
    space_id = sqlite3_last_insert_rowid(db.handle());

    // The clips of this skeleton, each of which must come with its projection.
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement clips,
                              db.Prepare("SELECT clip_id FROM clips WHERE skeleton_id = ?"));
    clips.BindInt64(1, skeleton_id);
    absl::flat_hash_set<int64_t> needed;
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, clips.Step());
      if (!row) break;
      needed.insert(clips.ColumnInt64(0));
    }
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement insert_projection, PrepareProjectionInsert(db));
    for (const Projection& projection : projections) {
      if (needed.erase(projection.clip_id) == 0) {
        MOTIONDB_ASSIGN_OR_RETURN(
            const bool exists,
            Exists(db, "SELECT 1 FROM clips WHERE clip_id = ?", projection.clip_id));
        if (!exists) {
          return absl::NotFoundError(absl::StrCat("clip ", projection.clip_id, " not found"));
        }
        return absl::FailedPreconditionError(absl::StrCat(
            "clip ", projection.clip_id, " belongs to another skeleton than the space's"));
      }
      MOTIONDB_RETURN_IF_ERROR(InsertProjection(insert_projection, space_id, projection.clip_id,
                                                projection.coordinates));
    }
    if (!needed.empty()) {
      return absl::FailedPreconditionError(absl::StrCat(
          "no projection of clip ", *std::min_element(needed.begin(), needed.end()),
          " of the space's skeleton; a space is stored with the projections of all its clips"));
    }
    return absl::OkStatus();
  }));
  return space_id;
}

absl::StatusOr<SpaceRecord> Database::GetSpaceRecord(const std::string& name) {
  SpaceRecord record;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(absl::StrCat("SELECT ", kSpaceRecordColumns, " FROM spaces WHERE name = ?")));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindText(1, name).Step());
    if (!found) return absl::NotFoundError(absl::StrCat("space '", name, "' not found"));
    record = ReadSpaceRecord(query);
    return absl::OkStatus();
  }));
  return record;
}

absl::StatusOr<MotionSpace> Database::GetSpace(int64_t space_id) {
  std::optional<MotionSpace> space;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              db.Prepare("SELECT data FROM spaces WHERE space_id = ?"));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindInt64(1, space_id).Step());
    if (!found) return absl::NotFoundError(absl::StrCat("space ", space_id, " not found"));
    absl::StatusOr<MotionSpace> parsed = ParseSpace(query.ColumnBlob(0));
    // Bytes this code wrote that no longer parse are damage, whatever ParseSpace calls it.
    if (!parsed.ok()) {
      return absl::DataLossError(
          absl::StrCat("stored space ", space_id, ": ", parsed.status().message()));
    }
    space.emplace(*std::move(parsed));
    return absl::OkStatus();
  }));
  return *std::move(space);
}

absl::StatusOr<std::vector<SpaceRecord>> Database::ListSpaces() {
  std::vector<SpaceRecord> records;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(absl::StrCat("SELECT ", kSpaceRecordColumns, " FROM spaces ORDER BY space_id")));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      records.push_back(ReadSpaceRecord(query));
    }
  }));
  return records;
}

absl::Status Database::DeleteSpace(const std::string& name) {
  return impl_->Write([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement erase,
                              db.Prepare("DELETE FROM spaces WHERE name = ?"));
    erase.BindText(1, name);
    return DeleteRow(db, erase, absl::StrCat("space '", name, "' not found"));
  });
}

absl::StatusOr<std::vector<Projection>> Database::LoadProjections(int64_t space_id) {
  std::vector<Projection> projections;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const bool exists,
                              Exists(db, "SELECT 1 FROM spaces WHERE space_id = ?", space_id));
    if (!exists) return absl::NotFoundError(absl::StrCat("space ", space_id, " not found"));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare("SELECT clip_id, frames, dims, data FROM projections WHERE space_id = ? "
                   "ORDER BY clip_id"));
    query.BindInt64(1, space_id);
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      Projection& projection = projections.emplace_back();
      projection.clip_id = query.ColumnInt64(0);
      absl::StatusOr<RowMatrixXf> coordinates = ParseFloat32Blob(
          query.ColumnBlob(3), query.ColumnInt64(1), query.ColumnInt64(2), "projection");
      if (!coordinates.ok()) {
        return Annotate(coordinates.status(),
                        absl::StrCat("space ", space_id, ", clip ", projection.clip_id, ": "));
      }
      projection.coordinates = *std::move(coordinates);
    }
  }));
  return projections;
}

absl::StatusOr<std::vector<int64_t>> Database::ClipsOfSkeleton(int64_t skeleton_id) {
  std::vector<int64_t> clip_ids;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const bool exists,
        Exists(db, "SELECT 1 FROM skeletons WHERE skeleton_id = ?", skeleton_id));
    if (!exists) return absl::NotFoundError(absl::StrCat("skeleton ", skeleton_id, " not found"));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare("SELECT clip_id FROM clips WHERE skeleton_id = ? ORDER BY clip_id"));
    query.BindInt64(1, skeleton_id);
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      clip_ids.push_back(query.ColumnInt64(0));
    }
  }));
  return clip_ids;
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
