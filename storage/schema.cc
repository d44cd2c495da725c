#include "storage/schema.h"

#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "storage/blob_codec.h"
#include "storage/content_hash.h"
#include "storage/sqlite_blob.h"
#include "storage/sqlite_transaction.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::storage {
namespace {

// Ids are AUTOINCREMENT where other rows, caches or clients refer to them, so that the id of a
// deleted clip, space or label is never handed to a new one.
constexpr const char* kMigration1 = R"sql(
-- Clips whose joint names and parents are identical share a skeleton. topology_key is the
-- canonical text of that topology (storage/blob_codec.h); names and parents are kept readable.
CREATE TABLE skeletons (
  skeleton_id INTEGER PRIMARY KEY,
  topology_key TEXT NOT NULL UNIQUE,
  joint_count INTEGER NOT NULL CHECK (joint_count > 0),
  joint_names TEXT NOT NULL,    -- one name a line
  joint_parents TEXT NOT NULL,  -- comma-separated parent indices, -1 for the root
  created_unix_ms INTEGER NOT NULL
);

-- Frames as little-endian float32: rotations frames x 4 joints (w, x, y, z), positions
-- frames x 3 position joints. layout is the clip's own skeleton (offsets and channels differ
-- between actors of one topology).
CREATE TABLE clips (
  clip_id INTEGER PRIMARY KEY AUTOINCREMENT,
  name TEXT NOT NULL UNIQUE,
  source_file TEXT NOT NULL,
  skeleton_id INTEGER NOT NULL REFERENCES skeletons (skeleton_id),
  frame_time REAL NOT NULL CHECK (frame_time > 0),
  frame_count INTEGER NOT NULL CHECK (frame_count >= 0),
  joint_count INTEGER NOT NULL CHECK (joint_count > 0),
  position_joint_count INTEGER NOT NULL CHECK (position_joint_count >= 0),
  layout BLOB NOT NULL,
  rotations BLOB NOT NULL CHECK (length(rotations) = 16 * frame_count * joint_count),
  positions BLOB NOT NULL CHECK (length(positions) = 12 * frame_count * position_joint_count),
  created_unix_ms INTEGER NOT NULL
);
CREATE INDEX clips_by_skeleton ON clips (skeleton_id, clip_id);

CREATE TABLE clip_tags (
  clip_id INTEGER NOT NULL REFERENCES clips (clip_id) ON DELETE CASCADE,
  tag TEXT NOT NULL CHECK (length(tag) > 0),
  PRIMARY KEY (clip_id, tag)
) WITHOUT ROWID;
CREATE INDEX clip_tags_by_tag ON clip_tags (tag, clip_id);

-- data is SerializeSpace (core/space_serialization.h): versioned and checksummed.
CREATE TABLE spaces (
  space_id INTEGER PRIMARY KEY AUTOINCREMENT,
  name TEXT NOT NULL UNIQUE,
  skeleton_id INTEGER NOT NULL REFERENCES skeletons (skeleton_id),
  version INTEGER NOT NULL CHECK (version >= 1),
  dims INTEGER NOT NULL CHECK (dims > 0),
  created_unix_ms INTEGER NOT NULL,
  data BLOB NOT NULL,
  build_report_json TEXT NOT NULL
);
CREATE INDEX spaces_by_skeleton ON spaces (skeleton_id);

-- A clip's motion curve in a space: frames x dims little-endian float32.
CREATE TABLE projections (
  space_id INTEGER NOT NULL REFERENCES spaces (space_id) ON DELETE CASCADE,
  clip_id INTEGER NOT NULL REFERENCES clips (clip_id) ON DELETE CASCADE,
  frames INTEGER NOT NULL CHECK (frames >= 0),
  dims INTEGER NOT NULL CHECK (dims > 0),
  data BLOB NOT NULL CHECK (length(data) = 4 * frames * dims),
  PRIMARY KEY (space_id, clip_id)
);
-- Deleting a clip finds its projections through this index, not by a scan.
CREATE INDEX projections_by_clip ON projections (clip_id);

-- Markup (SPEC 5): manual labels, and propagated ones with the label, space and score they
-- came from and the job that wrote them (a re-run replaces its job's rows). Deleting a space
-- keeps the labels found in it, without the space.
CREATE TABLE labels (
  label_id INTEGER PRIMARY KEY AUTOINCREMENT,
  clip_id INTEGER NOT NULL REFERENCES clips (clip_id) ON DELETE CASCADE,
  first_frame INTEGER NOT NULL CHECK (first_frame >= 0),
  last_frame INTEGER NOT NULL CHECK (last_frame >= first_frame),
  descriptor TEXT NOT NULL CHECK (length(descriptor) > 0),
  value REAL NOT NULL CHECK (value BETWEEN 0 AND 1),
  origin TEXT NOT NULL CHECK (origin IN ('manual', 'propagated')),
  source_label_id INTEGER REFERENCES labels (label_id) ON DELETE CASCADE,
  space_id INTEGER REFERENCES spaces (space_id) ON DELETE SET NULL,
  score REAL,
  job_id TEXT,
  created_unix_ms INTEGER NOT NULL
);
CREATE INDEX labels_by_descriptor ON labels (descriptor, value);
CREATE INDEX labels_by_clip ON labels (clip_id, first_frame);
-- For the cascades and for replacing a job's output.
CREATE INDEX labels_by_source ON labels (source_label_id);
CREATE INDEX labels_by_space ON labels (space_id);
CREATE INDEX labels_by_job ON labels (job_id);
)sql";

// Each clip's content hash (storage/content_hash.h), by which an ingest recognises a file it
// has stored before. '' is only ever seen by the backfill below, which runs in the migration's
// transaction.
constexpr const char* kMigration2 = R"sql(
ALTER TABLE clips ADD COLUMN content_hash TEXT NOT NULL DEFAULT '';
CREATE INDEX clips_by_content_hash ON clips (content_hash);
)sql";

// Background jobs (SPEC 7): a propagation job's row, its state, progress and counts, and its
// parameters as JSON text (the job's starter decides what they hold). The number is the
// AUTOINCREMENT key, so that a job id ("job-N") is never handed to a second job: labels keep
// the id of the job that wrote them.
constexpr const char* kMigration3 = R"sql(
CREATE TABLE jobs (
  job_number INTEGER PRIMARY KEY AUTOINCREMENT,
  kind TEXT NOT NULL CHECK (kind IN ('propagation')),
  state TEXT NOT NULL CHECK (state IN ('queued', 'running', 'succeeded', 'failed', 'cancelled',
                                       'interrupted')),
  parameters TEXT NOT NULL,
  done INTEGER NOT NULL DEFAULT 0 CHECK (done >= 0),
  total INTEGER NOT NULL DEFAULT 0 CHECK (total >= 0),
  queries INTEGER NOT NULL DEFAULT 0,
  queries_skipped INTEGER NOT NULL DEFAULT 0,
  labels_written INTEGER NOT NULL DEFAULT 0,
  error TEXT NOT NULL DEFAULT '',
  created_unix_ms INTEGER NOT NULL,
  started_unix_ms INTEGER NOT NULL DEFAULT 0,
  finished_unix_ms INTEGER NOT NULL DEFAULT 0
);
-- Open() finds the jobs a dead process left unfinished through this index.
CREATE INDEX jobs_by_state ON jobs (state);
)sql";

// The Motion Curve operators (issue 16): where a clip made by an operator came from (JSON text
// the application writes: operator, space, source ranges, parameters; '' for an ingested clip),
// and the pose models of pose detection by name, each of one space (deleted with it), stored as
// the text of core/ops/pose_model_serialization.h.
constexpr const char* kMigration4 = R"sql(
ALTER TABLE clips ADD COLUMN provenance TEXT NOT NULL DEFAULT '';
CREATE TABLE pose_models (
  model_id INTEGER PRIMARY KEY AUTOINCREMENT,
  name TEXT NOT NULL UNIQUE,
  space_id INTEGER NOT NULL REFERENCES spaces (space_id) ON DELETE CASCADE,
  data TEXT NOT NULL,
  parameters TEXT NOT NULL,
  created_unix_ms INTEGER NOT NULL
);
CREATE INDEX pose_models_by_space ON pose_models (space_id);
)sql";

// Each clip's rotation blob, its largest by far, moved to the end of its row (issue 15): an
// insert then binds it as a zero blob, which SQLite keeps as a count only when no column with
// bytes follows it, and writes it in pieces (sqlite3_blob_write), so that storing a clip never
// holds a second copy of it in memory (a blob elsewhere in the row is copied into the record
// being built, a zero blob expanded). Any column added to clips later lands after it and must
// hold no bytes for that to stay true (the schema tests check the last column). SQLite cannot
// move a column: a new one is added, filled by CopyRotationsLast, the old dropped, the new
// renamed. A column added to rows that exist cannot be NOT NULL without a default, so triggers
// refuse NULL instead.
constexpr const char* kMigration5 = R"sql(
ALTER TABLE clips ADD COLUMN rotations_last BLOB
  CHECK (length(rotations_last) = 16 * frame_count * joint_count);
)sql";
constexpr const char* kMigration5Finish = R"sql(
ALTER TABLE clips DROP COLUMN rotations;
ALTER TABLE clips RENAME COLUMN rotations_last TO rotations;
CREATE TRIGGER clips_rotations_insert_not_null BEFORE INSERT ON clips
  WHEN NEW.rotations IS NULL
  BEGIN SELECT RAISE(ABORT, 'NOT NULL constraint failed: clips.rotations'); END;
CREATE TRIGGER clips_rotations_update_not_null BEFORE UPDATE OF rotations ON clips
  WHEN NEW.rotations IS NULL
  BEGIN SELECT RAISE(ABORT, 'NOT NULL constraint failed: clips.rotations'); END;
)sql";

// Migration 5's copy, a row at a time and in 1 MiB pieces: one `UPDATE clips SET
// rotations_last = rotations` held each blob several times over (measured: +1.4 GiB for one
// 286 MiB blob) and a statement journal of the whole table on disk.
absl::Status CopyRotationsLast(SqliteConnection& connection) {
  std::vector<std::pair<int64_t, int64_t>> clips;  // id, rotation bytes
  {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement sizes,
        connection.Prepare("SELECT clip_id, length(rotations) FROM clips ORDER BY clip_id"));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, sizes.Step());
      if (!row) break;
      clips.emplace_back(sizes.ColumnInt64(0), sizes.ColumnInt64(1));
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement make_room,
      connection.Prepare("UPDATE clips SET rotations_last = ? WHERE clip_id = ?"));
  std::string piece;
  for (const auto& [clip_id, bytes] : clips) {
    make_room.Reset();
    MOTIONDB_RETURN_IF_ERROR(make_room.BindZeroBlob(1, bytes).BindInt64(2, clip_id).Run());
    using Mode = SqliteBlob::Mode;
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteBlob from, SqliteBlob::Open(connection, "clips", "rotations", clip_id, Mode::kRead));
    MOTIONDB_ASSIGN_OR_RETURN(SqliteBlob to, SqliteBlob::Open(connection, "clips", "rotations_last",
                                                              clip_id, Mode::kWrite));
    for (int64_t offset = 0; offset < bytes; offset += static_cast<int64_t>(piece.size())) {
      const int64_t count = std::min<int64_t>(bytes - offset, kFloat32PieceBytes);
      MOTIONDB_RETURN_IF_ERROR(from.Read(offset, count, piece));
      MOTIONDB_RETURN_IF_ERROR(to.Write(piece, offset));
    }
  }
  return absl::OkStatus();
}

// AddLabels looks for a label identical to each it is given, so as not to store it twice
// (issue 37): labels_by_clip takes the rest of what identifies a label, so that the lookup is
// one seek however many labels a clip has on one first frame (measured: 50,000 labels of one
// clip's range, each its own descriptor, took 284 s to import with the index on clip_id and
// first_frame alone, 1.2 s with this one). Its old columns lead it: what used them still does.
constexpr const char* kMigration6 = R"sql(
DROP INDEX labels_by_clip;
CREATE INDEX labels_by_clip ON labels (clip_id, first_frame, last_frame, descriptor, value);
)sql";

// The humanoid map (issue 40): a slot of a skeleton's map (core/motion/humanoid_map.h, by
// HumanoidSlotName) given its joint by hand, by the joint's name, over the automatic map.
constexpr const char* kMigration7 = R"sql(
CREATE TABLE skeleton_slot_overrides (
  skeleton_id INTEGER NOT NULL REFERENCES skeletons (skeleton_id) ON DELETE CASCADE,
  slot TEXT NOT NULL CHECK (length(slot) > 0),
  joint_name TEXT NOT NULL CHECK (length(joint_name) > 0),
  PRIMARY KEY (skeleton_id, slot)
) WITHOUT ROWID;
)sql";

// What an FBX or glTF file said of itself (issue 40), kept for each of its clips. A table of
// its own: a column of clips would follow the rotations and must hold no bytes (migration 5).
constexpr const char* kMigration8 = R"sql(
CREATE TABLE clip_sources (
  clip_id INTEGER PRIMARY KEY REFERENCES clips (clip_id) ON DELETE CASCADE,
  format TEXT NOT NULL CHECK (length(format) > 0),
  unit_m REAL NOT NULL CHECK (unit_m >= 0),
  up_axis TEXT NOT NULL
);
)sql";

// The skeletons of a space over several (issue 40 item 3), its spaces.skeleton_id among them: a
// clip of any of them is projected into the space. A space over one skeleton has no rows here.
constexpr const char* kMigration9 = R"sql(
CREATE TABLE space_skeletons (
  space_id INTEGER NOT NULL REFERENCES spaces (space_id) ON DELETE CASCADE,
  skeleton_id INTEGER NOT NULL REFERENCES skeletons (skeleton_id),
  PRIMARY KEY (space_id, skeleton_id)
) WITHOUT ROWID;
CREATE INDEX space_skeletons_by_skeleton ON space_skeletons (skeleton_id, space_id);
)sql";

// Hashes the clips stored before migration 2. SQLite has no SHA-256, so this is C++; one clip's
// blobs are in memory at a time.
absl::Status BackfillContentHashes(SqliteConnection& connection) {
  std::vector<int64_t> clip_ids;
  {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement unhashed,
        connection.Prepare("SELECT clip_id FROM clips WHERE content_hash = '' ORDER BY clip_id"));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, unhashed.Step());
      if (!row) break;
      clip_ids.push_back(unhashed.ColumnInt64(0));
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement read,
      connection.Prepare(
          "SELECT frame_time, layout, rotations, positions FROM clips WHERE clip_id = ?"));
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement update,
      connection.Prepare("UPDATE clips SET content_hash = ? WHERE clip_id = ?"));
  for (const int64_t clip_id : clip_ids) {
    read.Reset();
    MOTIONDB_RETURN_IF_ERROR(read.BindInt64(1, clip_id).Step().status());
    MOTIONDB_ASSIGN_OR_RETURN(const std::string hash,
                              ContentHashOfBlobs(read.ColumnDouble(0), read.ColumnBlob(1),
                                                 read.ColumnBlob(2), read.ColumnBlob(3)));
    update.Reset();
    MOTIONDB_RETURN_IF_ERROR(update.BindText(1, hash).BindInt64(2, clip_id).Run());
  }
  return absl::OkStatus();
}

// A schema step: its SQL, then the C++ that fills what SQL cannot (or null), then SQL that
// needs what the C++ filled (or null).
struct Migration {
  const char* sql;
  absl::Status (*backfill)(SqliteConnection& connection) = nullptr;
  const char* finish_sql = nullptr;
};

// Append only: a file at version i has run exactly the first i entries.
// clang-format off
constexpr std::array kMigrations = {
    Migration{kMigration1},
    Migration{kMigration2, BackfillContentHashes},
    Migration{kMigration3},
    Migration{kMigration4},
    Migration{kMigration5, CopyRotationsLast, kMigration5Finish},
    Migration{kMigration6},
    Migration{kMigration7},
    Migration{kMigration8},
    Migration{kMigration9},
};
// clang-format on

// A migration that rewrites a table (5 rewrites the clips twice) leaves its old pages free in
// the file, which would keep up to twice its size until later writes reuse them: VACUUM when
// more than a quarter of the file is free (measured: 4.7 s for a 714 MB file after migration
// 5), then empty the write-ahead log the rewrites filled. Best effort: the file is whole and
// migrated either way. VACUUM fails for want of disk (it writes a copy of the file) or while
// another process holds the write lock; the file then keeps its size, its free pages reused by
// later writes (`sqlite3 FILE VACUUM` offline compacts it; server/README.md).
void ReclaimFreedPages(SqliteConnection& connection) {
  const absl::StatusOr<int64_t> free_pages = connection.QueryInt64("PRAGMA freelist_count");
  const absl::StatusOr<int64_t> pages = connection.QueryInt64("PRAGMA page_count");
  if (free_pages.ok() && pages.ok() && 4 * *free_pages > *pages) {
    connection.Execute("VACUUM").IgnoreError();
    connection.Execute("PRAGMA wal_checkpoint(TRUNCATE)").IgnoreError();
  }
}

}  // namespace

int LatestSchemaVersion() { return static_cast<int>(kMigrations.size()); }

absl::Status CheckSchemaVersion(SqliteConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t version, connection.QueryInt64("PRAGMA user_version"));
  if (version > LatestSchemaVersion()) {
    return absl::FailedPreconditionError(absl::StrCat(
        "the database has schema version ", version, ", newer than version ", LatestSchemaVersion(),
        " that this build of motiondb reads; upgrade motiondb"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t application,
                            connection.QueryInt64("PRAGMA application_id"));
  if (application != 0 && application != kApplicationId) {
    return absl::FailedPreconditionError(absl::StrCat(
        "the file is a SQLite database of another application (application_id ", application, ")"));
  }
  if (version == 0) {
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t objects,
                              connection.QueryInt64("SELECT count(*) FROM sqlite_schema"));
    if (objects > 0) {
      return absl::FailedPreconditionError(
          absl::StrCat("the file is a SQLite database of another application (", objects,
                       " schema objects but no motiondb schema version)"));
    }
  }
  return absl::OkStatus();
}

absl::Status MigrateSchema(SqliteConnection& connection, int target_version) {
  if (target_version < 1 || target_version > LatestSchemaVersion()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "target_version must be 1 to ", LatestSchemaVersion(), ", got ", target_version));
  }
  MOTIONDB_ASSIGN_OR_RETURN(SqliteTransaction transaction,
                            SqliteTransaction::Begin(connection, SqliteTransaction::Kind::kWrite));
  // Checked again under the write lock: another process may have migrated meanwhile.
  MOTIONDB_RETURN_IF_ERROR(CheckSchemaVersion(connection));
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t version, connection.QueryInt64("PRAGMA user_version"));
  if (version >= target_version) return absl::OkStatus();
  for (int next = static_cast<int>(version) + 1; next <= target_version; ++next) {
    const Migration& migration = kMigrations[next - 1];
    const std::string step = absl::StrCat("schema migration ", next);
    MOTIONDB_RETURN_IF_ERROR(Prefixed(step, connection.Execute(migration.sql)));
    if (migration.backfill != nullptr) {
      MOTIONDB_RETURN_IF_ERROR(Prefixed(step, migration.backfill(connection)));
    }
    if (migration.finish_sql != nullptr) {
      MOTIONDB_RETURN_IF_ERROR(Prefixed(step, connection.Execute(migration.finish_sql)));
    }
  }
  // PRAGMAs take no parameters; both values are numbers of ours.
  MOTIONDB_RETURN_IF_ERROR(connection.Execute(absl::StrCat(
      "PRAGMA application_id = ", kApplicationId, "; PRAGMA user_version = ", target_version)));
  MOTIONDB_RETURN_IF_ERROR(transaction.Commit());
  ReclaimFreedPages(connection);
  return absl::OkStatus();
}

}  // namespace motiondb::storage
