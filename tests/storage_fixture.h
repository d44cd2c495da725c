// The fixture of the SQLite storage's tests (storage_*_test.cc): a fresh directory for one test's
// database file, humanoid clips and a space for the tests of spaces and projections, and the
// helpers that build clips, records and labels and compare what was read with what was written.
#ifndef MOTIONDB_TESTS_STORAGE_FIXTURE_H_
#define MOTIONDB_TESTS_STORAGE_FIXTURE_H_

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/motion/clip.h"
#include "core/motion/skeleton.h"
#include "core/space/motion_space.h"
#include "storage/database.h"
#include "storage/schema.h"
#include "storage/sqlite_connection.h"
#include "tests/clip_builder.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb::storage {

// The counts as a tuple, to compare them whole.
std::tuple<int64_t, int64_t, int64_t, int64_t, int64_t, int64_t> AsTuple(const Counts& c);

// `skeleton` with every offset and End Site scaled: another actor of the same topology.
std::shared_ptr<const Skeleton> Rescaled(const Skeleton& skeleton, double scale);

// A clip of `frames` frames whose rotations and positions vary with `seed`.
Clip Motion(std::shared_ptr<const Skeleton> skeleton, int frames, int seed = 0);

Page Sized(int page_size);

ClipRecord Named(const std::string& name, std::vector<std::string> tags = {});

void ExpectSameLayout(const Skeleton& a, const Skeleton& b);

void ExpectSameFrames(const Clip& expected, const Clip& actual);

// A manual label.
LabelRecord Manual(int64_t clip_id, int64_t first, int64_t last, const std::string& descriptor,
                   double value);

std::vector<int64_t> IdsOf(const std::vector<LabelRecord>& labels);

// The ids of a batch AddLabels stored, in its order.
absl::StatusOr<std::vector<int64_t>> IdsOf(const absl::StatusOr<AddedLabels>& added);

// A fresh directory for one test's database file.
class StorageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("storage_test");
    path_ = (dir_ / "motion.db").string();
  }
  void TearDown() override {
    db_.reset();
    std::filesystem::remove_all(dir_);
  }

  Database& Db() {
    if (db_ == nullptr) {
      absl::StatusOr<std::unique_ptr<Database>> db = Database::Open(path_);
      EXPECT_TRUE(db.ok()) << db.status();
      db_ = *std::move(db);
    }
    return *db_;
  }
  void Close() { db_.reset(); }

  int64_t Insert(const ClipRecord& record, const Clip& clip,
                 const std::vector<std::pair<int64_t, Projection>>& projections = {}) {
    const absl::StatusOr<int64_t> id = Db().InsertClip(record, clip, projections);
    EXPECT_TRUE(id.ok()) << id.status();
    return id.value_or(-1);
  }
  Counts CountsNow() {
    const absl::StatusOr<Counts> counts = Db().GetCounts();
    EXPECT_TRUE(counts.ok()) << counts.status();
    return counts.value_or(Counts{});
  }
  // Stores `walk` as "walk" (tagged x), then "session1/run" of `run_frames` frames: the two
  // records by id, for the tests of older schemas.
  std::map<int64_t, ClipRecord> StoreWalkAndRun(const Clip& walk, int run_frames) {
    const int64_t a = Insert(Named("walk", {"x"}), walk);
    const int64_t b =
        Insert(Named("session1/run"), Motion(testing::ChainSkeleton(), run_frames, 2));
    std::map<int64_t, ClipRecord> records;
    for (const int64_t id : {a, b}) records[id] = *Db().GetClipRecord(id);
    return records;
  }
  // Expects the clip `id` readable, with `expected`'s name, tags, content hash and frames.
  void ExpectKept(int64_t id, const ClipRecord& expected) {
    const absl::StatusOr<ClipRecord> record = Db().GetClipRecord(id);
    ASSERT_TRUE(record.ok()) << record.status();
    EXPECT_EQ(record->name, expected.name);
    EXPECT_EQ(record->tags, expected.tags);
    EXPECT_EQ(record->content_hash, expected.content_hash);
    EXPECT_EQ(record->frame_count, expected.frame_count);
    const absl::StatusOr<StoredClip> stored = Db().GetClip(id);
    EXPECT_TRUE(stored.ok()) << stored.status();
  }
  // Closes the database and copies its skeletons, clips and tags into a new file at schema
  // `version`, made by its own migrations, whose clips table has `clip_columns`; path_ then names
  // that file. Checks the copy has the version and lacks `missing_column` of clips (unless
  // empty).
  void CopyToOldSchema(int version, const std::string& clip_columns,
                       const std::string& missing_column) {
    Close();
    const std::string old_path = (dir_ / absl::StrCat("schema", version, ".db")).string();
    absl::StatusOr<std::unique_ptr<SqliteConnection>> old =
        SqliteConnection::Open(old_path, SqliteConnection::Mode::kReadWriteCreate, 1000);
    ASSERT_TRUE(old.ok()) << old.status();
    // In WAL mode, as every build's server leaves its file.
    ASSERT_EQ(*(*old)->QueryText("PRAGMA journal_mode = WAL"), "wal");
    ASSERT_TRUE(MigrateSchema(**old, version).ok());
    const absl::Status copied = (*old)->Execute(absl::StrCat(
        "ATTACH DATABASE '", path_, "' AS current;",
        "INSERT INTO skeletons SELECT * FROM current.skeletons;", "INSERT INTO clips SELECT ",
        clip_columns, " FROM current.clips;",
        "INSERT INTO clip_tags SELECT * FROM current.clip_tags;", "DETACH DATABASE current"));
    ASSERT_TRUE(copied.ok()) << copied;
    EXPECT_EQ(*(*old)->QueryInt64("PRAGMA user_version"), version);
    if (!missing_column.empty()) {
      EXPECT_EQ(*(*old)->QueryInt64(
                    absl::StrCat("SELECT count(*) FROM pragma_table_info('clips') WHERE name = '",
                                 missing_column, "'")),
                0);
    }
    path_ = old_path;
  }
  // A raw connection, to look at and damage what the Database wrote.
  std::unique_ptr<SqliteConnection> Raw() {
    auto raw = SqliteConnection::Open(path_, SqliteConnection::Mode::kReadWrite, 1000);
    EXPECT_TRUE(raw.ok()) << raw.status();
    return *std::move(raw);
  }

  std::filesystem::path dir_;
  std::string path_;
  std::unique_ptr<Database> db_;
};

// Humanoid clips and a space built on the first, for the tests of spaces and projections.
class StorageSpaceTest : public StorageTest {
 protected:
  StorageSpaceTest()
      : skeleton_(testing::HumanoidSkeleton(/*still_root=*/true)),
        walk_(testing::SyntheticClip(skeleton_, {.frames = 90, .seed = 1})),
        wave_(testing::SyntheticClip(Rescaled(*skeleton_, 1.1), {.frames = 70, .seed = 2})),
        space_(*MotionSpace::Build({{"walk.bvh", walk_, std::nullopt}})) {}

  Projection ProjectionOf(int64_t clip_id, const Clip& clip, int dims = 8) {
    Projection projection;
    projection.clip_id = clip_id;
    projection.coordinates = space_.ProjectClip(clip, dims)->cast<float>();
    return projection;
  }
  SpaceRecord SpaceNamed(const std::string& name, int64_t skeleton_id) {
    SpaceRecord record;
    record.name = name;
    record.skeleton_id = skeleton_id;
    record.version = 3;
    record.build_report_json = R"({"dims": 8})";
    return record;
  }

  // The walk and the wave, the space "body" on both, and two manual labels of the walk.
  struct LabelledLibrary {
    int64_t walk = 0, wave = 0, space_id = 0;
    std::vector<int64_t> manual;  // "kick" on 0-9 (value 1), "wave" on 20-29 (0.8)
  };
  LabelledLibrary InsertLabelledLibrary();

  std::shared_ptr<const Skeleton> skeleton_;
  Clip walk_;
  Clip wave_;
  MotionSpace space_;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_TESTS_STORAGE_FIXTURE_H_
