// The SQLite storage's database file (storage_fixture.h): schema versions and their migration,
// rotations written in pieces, foreign and damaged files, locks, backups and readers beside a
// writer, and a writer killed mid-stream.
#include "storage/database.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "storage/blob_codec.h"
#include "storage/content_hash.h"
#include "storage/schema.h"
#include "storage/sqlite_connection.h"
#include "tests/clip_builder.h"
#include "tests/storage_fixture.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb::storage {
namespace {

using ::testing::HasSubstr;

TEST_F(StorageTest, NewerSchemaVersionIsRefused) {
  Insert(Named("walk"), Motion(testing::ChainSkeleton(), 3));
  Close();
  ASSERT_TRUE(
      Raw()->Execute(absl::StrCat("PRAGMA user_version = ", LatestSchemaVersion() + 1)).ok());
  const absl::StatusOr<std::unique_ptr<Database>> db = Database::Open(path_);
  EXPECT_EQ(db.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(db.status().message(), HasSubstr("newer"));
}

// A file of schema version 1, as builds before the content hash wrote it, gets every clip's hash
// when opened: the hash a clip stored now would have.
TEST_F(StorageTest, SchemaOneFileIsMigratedAndBackfilled) {
  const Clip walk = Motion(testing::ChainSkeleton(), 20, 1);
  const int64_t a = Insert(Named("walk", {"x"}), walk);
  const int64_t b = Insert(Named("session1/run"), Motion(testing::ChainSkeleton(), 30, 2));
  const int64_t c = Insert(Named("walk_again"), walk);
  std::map<int64_t, std::string> expected;
  for (const int64_t id : {a, b, c}) expected[id] = Db().GetClipRecord(id)->content_hash;
  Close();

  // Version 1's schema, made by its own migration, holding the same rows.
  CopyToOldSchema(1,
                  "clip_id, name, source_file, skeleton_id, frame_time, frame_count, joint_count, "
                  "position_joint_count, layout, rotations, positions, created_unix_ms",
                  "content_hash");

  for (const int64_t id : {a, b, c}) {
    const absl::StatusOr<ClipRecord> record = Db().GetClipRecord(id);
    ASSERT_TRUE(record.ok()) << record.status();
    EXPECT_EQ(record->content_hash, expected[id]) << id;
  }
  EXPECT_THAT(Db().GetClipRecord(a)->tags, ::testing::ElementsAre("x"));
  const absl::StatusOr<std::vector<ClipRecord>> same = Db().FindClipsByContentHash(expected[a], 10);
  ASSERT_TRUE(same.ok()) << same.status();
  ASSERT_EQ(same->size(), 2u);
  EXPECT_EQ((*same)[1].clip_id, c);
  std::unique_ptr<SqliteConnection> raw = Raw();
  EXPECT_EQ(*raw->QueryInt64("PRAGMA user_version"), LatestSchemaVersion());
  EXPECT_EQ(*raw->QueryInt64("SELECT count(*) FROM clips WHERE content_hash = ''"), 0);
  EXPECT_EQ(
      *raw->QueryInt64("SELECT count(*) FROM sqlite_schema WHERE name = 'clips_by_content_hash'"),
      1);
  raw.reset();
  // New clips go on after the copied ids.
  EXPECT_GT(Insert(Named("new"), walk), c);
}

// The clips table's columns at schema version 4, for CopyToOldSchema.
constexpr const char* kSchemaFourClipColumns =
    "clip_id, name, source_file, skeleton_id, frame_time, frame_count, joint_count, "
    "position_joint_count, layout, rotations, positions, created_unix_ms, content_hash, "
    "provenance";

// The rotation blob, written in pieces after a zero blob (storage/sqlite_blob.h), holds exactly
// the bytes of the clip's rotations in float32, and the stored hash is that of the stored
// columns. 20000 frames of 19 joints are 5.8 MiB of rotations: six pieces, the last a part one.
TEST_F(StorageTest, RotationsWrittenInPiecesAreTheWholeBlob) {
  const std::shared_ptr<const Skeleton> skeleton = testing::HumanoidSkeleton(/*still_root=*/false);
  const Clip clip = Motion(skeleton, 20000, 4);
  ASSERT_GT(clip.rotations().size() * sizeof(float), 5 * kFloat32PieceBytes);
  ASSERT_NE(clip.rotations().size() * sizeof(float) % kFloat32PieceBytes, 0u);
  const int64_t id = Insert(Named("long"), clip);
  const std::string hash = Db().GetClipRecord(id)->content_hash;
  Close();
  {
    std::unique_ptr<SqliteConnection> raw = Raw();
    absl::StatusOr<SqliteStatement> row = raw->Prepare(
        "SELECT frame_time, layout, rotations, positions FROM clips WHERE clip_id = ?");
    ASSERT_TRUE(row.ok()) << row.status();
    ASSERT_TRUE(*row->BindInt64(1, id).Step());
    EXPECT_TRUE(row->ColumnBlob(2) == Float32Blob(clip.rotations()));
    EXPECT_EQ(*ContentHashOfBlobs(row->ColumnDouble(0), row->ColumnBlob(1), row->ColumnBlob(2),
                                  row->ColumnBlob(3)),
              hash);
  }
  EXPECT_EQ(*ContentHash(clip), hash);
  const absl::StatusOr<StoredClip> stored = Db().GetClip(id);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_TRUE(stored->clip.rotations().isApprox(clip.rotations(), 1e-6));
}

// A file of schema version 4 keeps its clips, bit for bit, when version 5 moves the rotation
// blob to the end of the row (so that an insert can write it in pieces), and a NULL rotation
// blob is refused as before, by a trigger now.
TEST_F(StorageTest, SchemaFourFileKeepsItsClipsWithTheRotationsLast) {
  const Clip walk = Motion(testing::ChainSkeleton(), 20, 1);
  // A run long enough that the rewrites leave most of the file free, and whose rotations
  // (25000 frames x 3 joints x 16 bytes, 1.14 MiB) are copied in two pieces.
  std::map<int64_t, ClipRecord> expected = StoreWalkAndRun(walk, 25000);
  const int64_t a = expected.begin()->first;
  const int64_t b = expected.rbegin()->first;
  CopyToOldSchema(4, kSchemaFourClipColumns, "");
  const std::string last_column =
      "SELECT name FROM pragma_table_info('clips') ORDER BY cid DESC LIMIT 1";
  EXPECT_EQ(*Raw()->QueryText(last_column), "provenance");
  std::map<int64_t, std::string> old_rotations;
  for (const int64_t id : {a, b}) {
    old_rotations[id] =
        *Raw()->QueryText(absl::StrCat("SELECT hex(rotations) FROM clips WHERE clip_id = ", id));
  }

  for (const int64_t id : {a, b}) ExpectKept(id, expected[id]);
  EXPECT_TRUE(Db().GetClip(a)->clip.rotations().isApprox(walk.rotations(), 1e-6));
  const int64_t c = Insert(Named("new"), walk);
  EXPECT_EQ(Db().GetClipRecord(c)->content_hash, expected[a].content_hash);
  Close();
  std::unique_ptr<SqliteConnection> raw = Raw();
  EXPECT_EQ(*raw->QueryInt64("PRAGMA user_version"), LatestSchemaVersion());
  EXPECT_EQ(*raw->QueryText(last_column), "rotations");
  // Migrated under a rollback journal, the file is back in WAL mode.
  EXPECT_EQ(*raw->QueryText("PRAGMA journal_mode"), "wal");
  // The pages the rewrites freed were given back (VACUUM): the file did not double.
  EXPECT_LE(4 * *raw->QueryInt64("PRAGMA freelist_count"), *raw->QueryInt64("PRAGMA page_count"));
  for (const int64_t id : {a, b}) {
    EXPECT_EQ(
        *raw->QueryText(absl::StrCat("SELECT hex(rotations) FROM clips WHERE clip_id = ", id)),
        old_rotations[id]);
  }
  const absl::Status null_update =
      raw->Execute(absl::StrCat("UPDATE clips SET rotations = NULL WHERE clip_id = ", a));
  EXPECT_THAT(null_update.message(), HasSubstr("NOT NULL constraint failed: clips.rotations"));
  const absl::Status null_insert = raw->Execute(
      "INSERT INTO clips (name, source_file, skeleton_id, frame_time, frame_count, joint_count, "
      "position_joint_count, layout, positions, created_unix_ms) SELECT 'null', '', skeleton_id, "
      "frame_time, frame_count, joint_count, position_joint_count, layout, positions, 0 "
      "FROM clips WHERE clip_id = " +
      std::to_string(a));
  EXPECT_THAT(null_insert.message(), HasSubstr("NOT NULL constraint failed: clips.rotations"));
  const absl::Status short_blob =
      raw->Execute(absl::StrCat("UPDATE clips SET rotations = x'00' WHERE clip_id = ", a));
  EXPECT_THAT(short_blob.message(), HasSubstr("CHECK constraint failed"));
}

// While another connection reads an older file, SQLite refuses to leave WAL mode, and the file
// migrates in WAL mode instead, rather than the open failing.
TEST_F(StorageTest, AnOlderFileMigratesWhileAnotherConnectionReadsIt) {
  const Clip walk = Motion(testing::ChainSkeleton(), 20, 1);
  std::map<int64_t, ClipRecord> expected = StoreWalkAndRun(walk, 30);
  CopyToOldSchema(4, kSchemaFourClipColumns, "");
  std::unique_ptr<SqliteConnection> reader = Raw();
  ASSERT_TRUE(reader->Execute("BEGIN").ok());
  ASSERT_EQ(*reader->QueryInt64("SELECT count(*) FROM clips"), 2);

  DatabaseOptions options;
  options.busy_timeout_ms = 100;
  absl::StatusOr<std::unique_ptr<Database>> db = Database::Open(path_, options);
  ASSERT_TRUE(db.ok()) << db.status();
  for (const auto& [id, record] : expected) {
    const absl::StatusOr<ClipRecord> migrated = (*db)->GetClipRecord(id);
    ASSERT_TRUE(migrated.ok()) << migrated.status();
    EXPECT_EQ(migrated->content_hash, record.content_hash);
  }
  ASSERT_TRUE(reader->Execute("COMMIT").ok());
  EXPECT_EQ(*reader->QueryInt64("PRAGMA user_version"), LatestSchemaVersion());
  EXPECT_EQ(*reader->QueryText("PRAGMA journal_mode"), "wal");
}

// A file of schema version 3, as builds before the operators (issue 16) wrote it, keeps its
// clips when opened and gains what version 4 adds: each clip's provenance (none for an ingested
// clip) and the pose models' table.
TEST_F(StorageTest, SchemaThreeFileKeepsItsClipsAndGainsProvenanceAndPoseModels) {
  const Clip walk = Motion(testing::ChainSkeleton(), 20, 1);
  std::map<int64_t, ClipRecord> expected = StoreWalkAndRun(walk, 30);
  const int64_t a = expected.begin()->first;
  const int64_t b = expected.rbegin()->first;

  CopyToOldSchema(3,
                  "clip_id, name, source_file, skeleton_id, frame_time, frame_count, joint_count, "
                  "position_joint_count, layout, rotations, positions, created_unix_ms, "
                  "content_hash",
                  "provenance");
  EXPECT_EQ(*Raw()->QueryInt64("SELECT count(*) FROM sqlite_schema WHERE name = 'pose_models'"), 0);

  for (const int64_t id : {a, b}) {
    ExpectKept(id, expected[id]);
    EXPECT_EQ(Db().GetClipRecord(id)->provenance, "");
  }
  EXPECT_EQ(Db().GetClip(a)->clip.frame_count(), 20);
  const absl::StatusOr<std::vector<PoseModelRecord>> models = Db().ListPoseModels();
  ASSERT_TRUE(models.ok()) << models.status();
  EXPECT_TRUE(models->empty());
  EXPECT_EQ(*Raw()->QueryInt64("PRAGMA user_version"), LatestSchemaVersion());
  // A clip made by an operator keeps where it came from.
  ClipRecord made = Named("made");
  made.provenance = R"({"operator":"smooth"})";
  const int64_t c = Insert(made, walk);
  EXPECT_GT(c, b);
  EXPECT_EQ(Db().GetClipRecord(c)->provenance, made.provenance);
}

TEST_F(StorageTest, ForeignFilesAreRefusedUntouched) {
  { std::ofstream(path_) << "name,frames\nwalk,120\n"; }
  const std::string bytes = testing::ReadFileOrDie(path_);
  const absl::StatusOr<std::unique_ptr<Database>> text = Database::Open(path_);
  EXPECT_EQ(text.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(text.status().message(), HasSubstr("not a SQLite database"));
  EXPECT_EQ(testing::ReadFileOrDie(path_), bytes);
  EXPECT_FALSE(std::filesystem::exists(path_ + "-wal"));
  std::filesystem::remove(path_);

  // Another application's SQLite database.
  ASSERT_TRUE(SqliteConnection::Open(path_, SqliteConnection::Mode::kReadWriteCreate, 0)
                  .value()
                  ->Execute("CREATE TABLE songs (title TEXT)")
                  .ok());
  const std::string sqlite_bytes = testing::ReadFileOrDie(path_);
  EXPECT_EQ(Database::Open(path_).status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(testing::ReadFileOrDie(path_), sqlite_bytes);

  EXPECT_EQ(
      Database::Open((dir_ / "absent.db").string(), {.create_if_missing = false}).status().code(),
      absl::StatusCode::kNotFound);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "absent.db"));
}

TEST_F(StorageTest, DamagedFileFailsToOpen) {
  for (int i = 0; i < 40; ++i)
    Insert(Named(absl::StrCat("clip_", i), {"tag"}), Motion(testing::ChainSkeleton(), 200, i));
  Close();
  const std::string bytes = testing::ReadFileOrDie(path_);
  constexpr size_t kPage = 4096;
  ASSERT_GT(bytes.size(), 20 * kPage);
  {
    // Garbage over a few whole pages in the middle: page headers and pointers included.
    std::fstream file(path_, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp((bytes.size() / kPage / 2) * kPage);
    const std::string garbage(4 * kPage, '\xA5');
    file.write(garbage.data(), garbage.size());
  }
  const absl::StatusOr<std::unique_ptr<Database>> db = Database::Open(path_);
  ASSERT_FALSE(db.ok());
  EXPECT_EQ(db.status().code(), absl::StatusCode::kFailedPrecondition) << db.status();
  EXPECT_THAT(db.status().message(), HasSubstr("integrity"));
}

TEST_F(StorageTest, LockedDatabaseIsUnavailableToWritersOnly) {
  Insert(Named("walk"), Motion(testing::ChainSkeleton(), 3));
  Close();
  absl::StatusOr<std::unique_ptr<Database>> db = Database::Open(path_, {.busy_timeout_ms = 50});
  ASSERT_TRUE(db.ok()) << db.status();
  // Another process's writer, as far as SQLite can tell.
  std::unique_ptr<SqliteConnection> other = Raw();
  ASSERT_TRUE(other->Execute("BEGIN IMMEDIATE; DELETE FROM clip_tags").ok());
  const absl::StatusOr<int64_t> id =
      (*db)->InsertClip(Named("run"), Motion(testing::ChainSkeleton(), 3), {});
  EXPECT_EQ(id.status().code(), absl::StatusCode::kUnavailable) << id.status();
  // Readers do not wait for the writer.
  const absl::StatusOr<Counts> counts = (*db)->GetCounts();
  ASSERT_TRUE(counts.ok()) << counts.status();
  EXPECT_EQ(counts->clips, 1);
  ASSERT_TRUE(other->Execute("ROLLBACK").ok());
  EXPECT_TRUE((*db)->InsertClip(Named("run"), Motion(testing::ChainSkeleton(), 3), {}).ok());
}

// A backup taken while a writer inserts clip after clip: the copy opens, passes integrity_check,
// holds every clip acknowledged before the backup began whole, and the writer never failed.
TEST_F(StorageSpaceTest, BackupIsAConsistentCopyWhileWritesGoOn) {
  const int64_t walk = Insert(Named("walk"), walk_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  ASSERT_TRUE(
      Db().InsertSpace(SpaceNamed("body", skeleton), space_, {ProjectionOf(walk, walk_)}).ok());
  const int64_t space_id = Db().GetSpaceRecord("body")->space_id;
  std::atomic<int64_t> acknowledged = 1;  // clips whose insert returned
  std::atomic<bool> stop = false;
  std::atomic<int> failures = 0;
  std::thread writer([&] {
    for (int i = 0; !stop; ++i) {
      const absl::StatusOr<int64_t> id = Db().InsertClip(Named(absl::StrCat("take_", i)), walk_,
                                                         {{space_id, ProjectionOf(0, walk_)}});
      if (id.ok()) {
        ++acknowledged;
      } else {
        ++failures;
      }
    }
  });
  while (acknowledged < 20) std::this_thread::yield();
  const std::string copy = (dir_ / "copy.sqlite").string();
  const int64_t before = acknowledged;
  const absl::Status backup = Db().Backup(copy, {});
  const int64_t after = acknowledged;
  stop = true;
  writer.join();
  ASSERT_TRUE(backup.ok()) << backup;
  EXPECT_EQ(failures, 0);

  std::unique_ptr<SqliteConnection> raw =
      *SqliteConnection::Open(copy, SqliteConnection::Mode::kReadOnly, 1000);
  EXPECT_EQ(*raw->QueryText("PRAGMA integrity_check"), "ok");
  raw.reset();
  absl::StatusOr<std::unique_ptr<Database>> copied =
      Database::Open(copy, {.create_if_missing = false});
  ASSERT_TRUE(copied.ok()) << copied.status();
  const Counts counts = *(*copied)->GetCounts();
  EXPECT_GE(counts.clips, before);
  // At most the inserts that returned during the backup (and the one in flight as it ended).
  EXPECT_LE(counts.clips, after + 1);
  EXPECT_EQ(counts.projections, counts.clips);
  // Every clip of the copy is whole, frames and projection.
  const absl::StatusOr<std::vector<Projection>> projections = (*copied)->LoadProjections(space_id);
  ASSERT_TRUE(projections.ok()) << projections.status();
  for (const Projection& projection : *projections) {
    const absl::StatusOr<StoredClip> stored = (*copied)->GetClip(projection.clip_id);
    ASSERT_TRUE(stored.ok()) << stored.status();
    ExpectSameFrames(walk_, stored->clip);
  }

  // A second backup to the same file: refused, the first copy untouched.
  const std::string first_copy = testing::ReadFileOrDie(copy);
  copied->reset();
  EXPECT_EQ(Db().Backup(copy, {}).code(), absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(testing::ReadFileOrDie(copy), first_copy);
  // A target that cannot be written: an error, and no file.
  const std::string unwritable = (dir_ / "missing_dir" / "copy.sqlite").string();
  EXPECT_FALSE(Db().Backup(unwritable, {}).ok());
  EXPECT_FALSE(std::filesystem::exists(unwritable));
}

TEST_F(StorageTest, ReadersRunBesideAWriter) {
  const Clip clip = Motion(testing::ChainSkeleton(), 30);
  const int64_t first = Insert(Named("seed", {"t"}), clip);
  std::atomic<bool> stop = false;
  std::atomic<int> failures = 0;
  std::atomic<int> reads = 0;
  std::vector<std::thread> threads;
  for (int w = 0; w < 2; ++w) {
    threads.emplace_back([&, w] {
      for (int i = 0; !stop; ++i) {
        if (!Db().InsertClip(Named(absl::StrCat("w", w, "_", i), {"t"}), clip, {}).ok()) ++failures;
      }
    });
  }
  for (int r = 0; r < 4; ++r) {
    threads.emplace_back([&] {
      int64_t last_count = 0;
      while (!stop) {
        const absl::StatusOr<Counts> counts = Db().GetCounts();
        const absl::StatusOr<StoredClip> stored = Db().GetClip(first);
        const absl::StatusOr<ClipPage> page = Db().ListClips(Sized(50), "t");
        if (!counts.ok() || !stored.ok() || !page.ok() || counts->clips < last_count ||
            counts->frames != 30 * counts->clips) {
          ++failures;
        } else {
          last_count = counts->clips;
        }
        ++reads;
      }
    });
  }
  // Until the readers have seen a good many writes (not for a time: a loaded machine is slow).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while ((reads < 200 || CountsNow().clips < 40) && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stop = true;
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(failures, 0);
  EXPECT_GE(reads, 200);
  EXPECT_GE(CountsNow().clips, 40);
}

// A writer SIGKILLed between and during commits: after reopening, the file passes its check,
// every acknowledged clip is there whole, and no clip is there in part.
TEST_F(StorageSpaceTest, KilledWriterLosesNoAcknowledgedClip) {
  const int64_t walk = Insert(Named("walk", {"a", "b"}), walk_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  const int64_t space_id =
      *Db().InsertSpace(SpaceNamed("body", skeleton), space_, {ProjectionOf(walk, walk_)});
  Close();
  const Clip big = testing::SyntheticClip(skeleton_, {.frames = 600, .seed = 4});
  const Projection projection = ProjectionOf(0, big);

  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The child writes until killed; it must never return into the test framework.
    close(pipe_fds[0]);
    absl::StatusOr<std::unique_ptr<Database>> db =
        Database::Open(path_, {.integrity_check = false});
    if (!db.ok()) _exit(2);
    for (int i = 0;; ++i) {
      const absl::StatusOr<int64_t> id =
          (*db)->InsertClip(Named(absl::StrCat("k", i), {"a", "b"}), big, {{space_id, projection}});
      if (!id.ok() || write(pipe_fds[1], &*id, sizeof(int64_t)) != sizeof(int64_t)) _exit(3);
    }
  }
  close(pipe_fds[1]);
  constexpr size_t kAcknowledged = 40;
  std::vector<int64_t> acknowledged;
  int64_t id = 0;
  while (acknowledged.size() < kAcknowledged && read(pipe_fds[0], &id, sizeof(id)) == sizeof(id)) {
    acknowledged.push_back(id);
  }
  kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "child exited with " << WEXITSTATUS(status);
  // Ids written before the signal landed were acknowledged too.
  while (read(pipe_fds[0], &id, sizeof(id)) == sizeof(id)) acknowledged.push_back(id);
  close(pipe_fds[0]);
  ASSERT_GE(acknowledged.size(), kAcknowledged);

  EXPECT_EQ(*Raw()->QueryText("PRAGMA quick_check"), "ok");
  const Counts counts = CountsNow();  // Open ran quick_check too
  // Every acknowledged clip, the first one, and at most the one committed but not yet reported.
  EXPECT_GE(counts.clips, static_cast<int64_t>(acknowledged.size()) + 1);
  EXPECT_LE(counts.clips, static_cast<int64_t>(acknowledged.size()) + 2);
  EXPECT_EQ(counts.projections, counts.clips);
  for (const int64_t clip_id : acknowledged) {
    const absl::StatusOr<StoredClip> stored = Db().GetClip(clip_id);
    ASSERT_TRUE(stored.ok()) << stored.status();
    EXPECT_EQ(stored->clip.frame_count(), 600);
    EXPECT_EQ(stored->record.tags.size(), 2u);
  }
  const absl::StatusOr<std::vector<Projection>> projections = Db().LoadProjections(space_id);
  ASSERT_TRUE(projections.ok()) << projections.status();
  EXPECT_EQ(static_cast<int64_t>(projections->size()), counts.clips);
  std::unique_ptr<SqliteConnection> raw = Raw();
  EXPECT_EQ(
      *raw->QueryInt64("SELECT count(*) FROM clips WHERE "
                       "length(rotations) != 16 * frame_count * joint_count OR "
                       "length(positions) != 12 * frame_count * position_joint_count OR "
                       "(SELECT count(*) FROM clip_tags t WHERE t.clip_id = clips.clip_id) != 2"),
      0);
}

}  // namespace
}  // namespace motiondb::storage
