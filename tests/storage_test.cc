// The SQLite storage layer on real files: round trips, pagination, skeleton sharing, spaces and
// projections, cascades, atomic failures, clip names and content hashes, replacing and updating
// clips, schema migration, damaged and foreign files, concurrency, and a writer killed
// mid-stream.
#include "storage/database.h"

#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cfloat>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/escaping.h"
#include "core/space/space_serialization.h"
#include "storage/blob_codec.h"
#include "storage/content_hash.h"
#include "storage/schema.h"
#include "storage/sqlite_connection.h"
#include "tests/clip_builder.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb::storage {
namespace {

using ::testing::HasSubstr;

std::tuple<int64_t, int64_t, int64_t, int64_t, int64_t, int64_t> AsTuple(const Counts& c) {
  return {c.skeletons, c.clips, c.frames, c.spaces, c.projections, c.labels};
}

// `skeleton` with every offset and End Site scaled: another actor of the same topology.
std::shared_ptr<const Skeleton> Rescaled(const Skeleton& skeleton, double scale) {
  std::vector<Joint> joints = skeleton.joints();
  for (Joint& joint : joints) {
    joint.offset *= scale;
    if (joint.end_site) *joint.end_site *= scale;
  }
  return std::make_shared<const Skeleton>(*Skeleton::Create(std::move(joints)));
}

// `skeleton` with its last joint renamed: another topology.
std::shared_ptr<const Skeleton> Renamed(const Skeleton& skeleton, const std::string& name) {
  std::vector<Joint> joints = skeleton.joints();
  joints.back().name = name;
  return std::make_shared<const Skeleton>(*Skeleton::Create(std::move(joints)));
}

// A clip of `frames` frames whose rotations and positions vary with `seed`.
Clip Motion(std::shared_ptr<const Skeleton> skeleton, int frames, int seed = 0) {
  return testing::MakeClip(
      std::move(skeleton), frames, 1.0 / 120.0,
      [seed](int f, int j) {
        return Quat(
            Eigen::AngleAxisd(0.37 * f + 1.1 * j + seed,
                              Eigen::Vector3d(1.0, 0.3 * j, 0.1 * seed + 0.2).normalized()));
      },
      [seed](int f, int j) { return Eigen::Vector3d(0.013 * f - 7.1, 91.7 + j, 3.3 * seed); });
}

Page Sized(int page_size) {
  Page page;
  page.page_size = page_size;
  return page;
}

ClipRecord Named(const std::string& name, std::vector<std::string> tags = {}) {
  ClipRecord record;
  record.name = name;
  record.source_file = name + ".bvh";
  record.tags = std::move(tags);
  return record;
}

void ExpectSameLayout(const Skeleton& a, const Skeleton& b) {
  ASSERT_EQ(a.joint_count(), b.joint_count());
  for (int j = 0; j < a.joint_count(); ++j) {
    EXPECT_EQ(a.joint(j).name, b.joint(j).name);
    EXPECT_EQ(a.joint(j).parent, b.joint(j).parent);
    EXPECT_EQ(a.joint(j).offset, b.joint(j).offset);
    EXPECT_EQ(a.joint(j).channels, b.joint(j).channels);
    EXPECT_EQ(a.joint(j).end_site, b.joint(j).end_site);
  }
}

void ExpectSameFrames(const Clip& expected, const Clip& actual) {
  EXPECT_EQ(actual.frame_time(), expected.frame_time());
  ASSERT_EQ(actual.frame_count(), expected.frame_count());
  ExpectSameLayout(expected.skeleton(), actual.skeleton());
  double worst_angle = 0.0;
  for (int f = 0; f < expected.frame_count(); ++f) {
    for (int j = 0; j < expected.skeleton().joint_count(); ++j) {
      worst_angle =
          std::max(worst_angle, AngleBetween(expected.rotation(f, j), actual.rotation(f, j)));
    }
  }
  EXPECT_LT(worst_angle, 1e-6);
  const RowMatrixXd& p = expected.positions();
  ASSERT_EQ(actual.positions().rows(), p.rows());
  ASSERT_EQ(actual.positions().cols(), p.cols());
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(actual.positions().data()[i], p.data()[i],
                1e-6 * std::max(1.0, std::abs(p.data()[i])));
  }
}

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

TEST_F(StorageTest, ClipRoundTripKeepsFramesLayoutAndRecord) {
  const Clip clip = Motion(testing::ChainSkeleton(), 50, 3);
  ClipRecord record = Named("walk_01", {"walk", "actor:b", "walk"});
  record.created_unix_ms = 1700000000123;
  const int64_t id = Insert(record, clip);
  ASSERT_GT(id, 0);

  const absl::StatusOr<StoredClip> stored = Db().GetClip(id);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(stored->record.clip_id, id);
  EXPECT_EQ(stored->record.name, "walk_01");
  EXPECT_EQ(stored->record.source_file, "walk_01.bvh");
  EXPECT_THAT(stored->record.tags, ::testing::ElementsAre("actor:b", "walk"));
  EXPECT_EQ(stored->record.created_unix_ms, 1700000000123);
  EXPECT_GT(stored->record.skeleton_id, 0);
  ExpectSameFrames(clip, stored->clip);

  const absl::StatusOr<ClipRecord> only_record = Db().GetClipRecord(id);
  ASSERT_TRUE(only_record.ok()) << only_record.status();
  EXPECT_EQ(only_record->name, "walk_01");
  EXPECT_EQ(only_record->tags, stored->record.tags);
  EXPECT_EQ(only_record->skeleton_id, stored->record.skeleton_id);

  const Counts counts = CountsNow();
  EXPECT_EQ(counts.clips, 1);
  EXPECT_EQ(counts.frames, 50);
  EXPECT_EQ(counts.skeletons, 1);

  // A clip without frames stores empty blobs.
  const int64_t empty = Insert(Named("empty"), Motion(testing::ChainSkeleton(), 0));
  const absl::StatusOr<StoredClip> stored_empty = Db().GetClip(empty);
  ASSERT_TRUE(stored_empty.ok()) << stored_empty.status();
  EXPECT_EQ(stored_empty->clip.frame_count(), 0);
}

// A range is read without the other frames and is the same as the whole clip's slice.
TEST_F(StorageTest, AFrameRangeReadsAsTheSliceOfTheClip) {
  const Clip clip = Motion(testing::ChainSkeleton(), 50, 3);
  const int64_t id = Insert(Named("walk_01"), clip);
  for (const FrameRange range : {FrameRange{0, 49}, FrameRange{10, 20}, FrameRange{49, 49}}) {
    const absl::StatusOr<StoredClip> stored = Db().GetClip(id, range);
    ASSERT_TRUE(stored.ok()) << stored.status();
    EXPECT_EQ(stored->record.frame_count, 50);  // the record is the whole clip's
    ExpectSameFrames(*clip.Slice(range), stored->clip);
  }
  for (const FrameRange range : {FrameRange{40, 50}, FrameRange{5, 4}, FrameRange{-1, 3}}) {
    EXPECT_EQ(Db().GetClip(id, range).status().code(), absl::StatusCode::kOutOfRange);
  }
  EXPECT_EQ(Db().GetClip(4242, FrameRange{0, 0}).status().code(), absl::StatusCode::kNotFound);
}

TEST_F(StorageTest, TagFilterListsOnlyTaggedClips) {
  const Clip clip = Motion(testing::ChainSkeleton(), 5);
  const int64_t a = Insert(Named("a", {"walk"}), clip);
  Insert(Named("b", {"run"}), clip);
  const int64_t c = Insert(Named("c", {"run", "walk"}), clip);
  Insert(Named("d"), clip);

  const absl::StatusOr<ClipPage> walks = Db().ListClips({}, "walk");
  ASSERT_TRUE(walks.ok()) << walks.status();
  ASSERT_EQ(walks->clips.size(), 2u);
  EXPECT_EQ(walks->clips[0].clip_id, a);
  EXPECT_EQ(walks->clips[1].clip_id, c);
  EXPECT_THAT(walks->clips[1].tags, ::testing::ElementsAre("run", "walk"));
  EXPECT_EQ(walks->next_page_token, "");
  EXPECT_EQ(Db().ListClips({}, "jump")->clips.size(), 0u);
  EXPECT_EQ(Db().ListClips({})->clips.size(), 4u);
}

TEST_F(StorageTest, ListClipsFiltersByNameAndPagesStablyInEachOrder) {
  const Clip clip = Motion(testing::ChainSkeleton(), 2);
  // Ids in insertion order; names and creation times in other orders, two times equal.
  const std::vector<std::pair<std::string, int64_t>> named = {
      {"s2/walk", 3000}, {"s1/walk", 1000}, {"s1/run", 2000}, {"s2/run.fast", 1000}, {"jump", 500}};
  std::map<std::string, int64_t> ids;
  for (const auto& [name, ms] : named) {
    ClipRecord record = Named(name, {"t"});
    record.created_unix_ms = ms;
    ids[name] = Insert(record, clip);
  }
  // Every clip `filter` lists, a page of two at a time, following the tokens.
  auto names = [&](const ClipFilter& filter) {
    std::vector<std::string> listed;
    Page page = Sized(2);
    for (int pages = 0; pages < 10; ++pages) {
      const absl::StatusOr<ClipPage> result = Db().ListClips(page, filter);
      EXPECT_TRUE(result.ok()) << result.status();
      if (!result.ok()) break;
      for (const ClipRecord& record : result->clips) listed.push_back(record.name);
      page.page_token = result->next_page_token;
      if (page.page_token.empty()) break;
    }
    return listed;
  };
  using ::testing::ElementsAre;
  EXPECT_THAT(names({.order = ClipOrder::kId}),
              ElementsAre("s2/walk", "s1/walk", "s1/run", "s2/run.fast", "jump"));
  EXPECT_THAT(names({.order = ClipOrder::kName}),
              ElementsAre("jump", "s1/run", "s1/walk", "s2/run.fast", "s2/walk"));
  // Equal times in id order.
  EXPECT_THAT(names({.order = ClipOrder::kCreated}),
              ElementsAre("jump", "s1/walk", "s2/run.fast", "s1/run", "s2/walk"));
  EXPECT_THAT(names({.name_contains = "run", .order = ClipOrder::kName}),
              ElementsAre("s1/run", "s2/run.fast"));
  EXPECT_THAT(names({.tag = "t", .name_contains = "s2/"}), ElementsAre("s2/walk", "s2/run.fast"));
  EXPECT_THAT(names({.name_contains = "WALK"}), ElementsAre());  // case-sensitive
  EXPECT_THAT(names({.name_contains = "%"}), ElementsAre());     // not a LIKE pattern

  // A name page's token holds its place while a clip before it goes and one after it comes.
  const absl::StatusOr<ClipPage> first = Db().ListClips(Sized(2), {.order = ClipOrder::kName});
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_TRUE(Db().DeleteClip(ids["jump"]).ok());
  Insert(Named("s1/sit"), clip);
  const absl::StatusOr<ClipPage> second = Db().ListClips(
      {.page_size = 2, .page_token = first->next_page_token}, {.order = ClipOrder::kName});
  ASSERT_TRUE(second.ok()) << second.status();
  ASSERT_EQ(second->clips.size(), 2u);
  EXPECT_EQ(second->clips[0].name, "s1/sit");
  EXPECT_EQ(second->clips[1].name, "s1/walk");

  // A token of one order is refused in another.
  EXPECT_EQ(Db().ListClips({.page_token = first->next_page_token}, ClipFilter{}).status().code(),
            absl::StatusCode::kInvalidArgument);
  for (const std::string token : {"n.1", "n.x.YQ", "c.1.x", "c.1", "n.1.@@"}) {
    EXPECT_EQ(Db().ListClips({.page_token = token}, {.order = ClipOrder::kName}).status().code(),
              absl::StatusCode::kInvalidArgument)
        << token;
  }
  EXPECT_EQ(
      Db().ListClips({.page_token = "n.1.YQ"}, {.order = ClipOrder::kCreated}).status().code(),
      absl::StatusCode::kInvalidArgument);
}

TEST_F(StorageTest, ListSkeletonsCountsClipsAndNamesTheFirst) {
  EXPECT_TRUE(Db().ListSkeletons()->empty());
  Insert(Named("b"), Motion(testing::ChainSkeleton(), 2));
  Insert(Named("a"), Motion(testing::ChainSkeleton(), 3));
  const int64_t humanoid = Insert(Named("h"), Motion(testing::HumanoidSkeleton(true), 2));
  const absl::StatusOr<std::vector<SkeletonSummary>> skeletons = Db().ListSkeletons();
  ASSERT_TRUE(skeletons.ok()) << skeletons.status();
  ASSERT_EQ(skeletons->size(), 2u);
  EXPECT_EQ((*skeletons)[0].root_joint, "root");
  EXPECT_EQ((*skeletons)[0].joint_count, 3);
  EXPECT_EQ((*skeletons)[0].clip_count, 2);
  EXPECT_EQ((*skeletons)[0].first_clip_name, "b");  // by id, not by name
  EXPECT_EQ((*skeletons)[1].root_joint, "Root");
  ASSERT_TRUE(Db().DeleteClip(humanoid).ok());
  const absl::StatusOr<std::vector<SkeletonSummary>> after = Db().ListSkeletons();
  ASSERT_EQ(after->size(), 2u);  // a skeleton outlives its clips
  EXPECT_EQ((*after)[1].clip_count, 0);
  EXPECT_EQ((*after)[1].first_clip_name, "");
}

TEST_F(StorageTest, PaginationVisitsEveryClipOnce) {
  const Clip clip = Motion(testing::ChainSkeleton(), 2);
  std::vector<int64_t> inserted;
  for (int i = 0; i < 250; ++i) {
    inserted.push_back(
        Insert(Named(absl::StrCat("clip_", i), {i % 3 == 0 ? "third" : "other"}), clip));
  }

  // Every page of `page_size` under `tag`, following the tokens to the end.
  auto all_pages = [&](int page_size, const std::string& tag) {
    std::vector<std::vector<int64_t>> pages;
    Page page = Sized(page_size);
    do {
      const absl::StatusOr<ClipPage> result = Db().ListClips(page, tag);
      EXPECT_TRUE(result.ok()) << result.status();
      if (!result.ok() || pages.size() > 20) break;
      pages.emplace_back();
      for (const ClipRecord& record : result->clips) pages.back().push_back(record.clip_id);
      page.page_token = result->next_page_token;
    } while (!page.page_token.empty());
    return pages;
  };

  const std::vector<std::vector<int64_t>> pages = all_pages(100, "");
  ASSERT_EQ(pages.size(), 3u);
  EXPECT_EQ(pages[0].size(), 100u);
  EXPECT_EQ(pages[1].size(), 100u);
  EXPECT_EQ(pages[2].size(), 50u);
  std::vector<int64_t> seen;
  for (const auto& page : pages) seen.insert(seen.end(), page.begin(), page.end());
  EXPECT_EQ(seen, inserted);  // in id order, no duplicates, no gaps

  std::vector<int64_t> thirds;
  for (size_t i = 0; i < inserted.size(); i += 3) thirds.push_back(inserted[i]);
  std::vector<int64_t> tagged;
  for (const auto& page : all_pages(30, "third"))
    tagged.insert(tagged.end(), page.begin(), page.end());
  EXPECT_EQ(tagged, thirds);

  EXPECT_EQ(Db().ListClips(Sized(0))->clips.size(), 100u);
  EXPECT_EQ(Db().ListClips(Sized(1000))->clips.size(), 250u);
  EXPECT_EQ(Db().ListClips(Sized(250))->next_page_token, "");
  for (const int size : {-1, 1001}) {
    EXPECT_EQ(Db().ListClips(Sized(size)).status().code(), absl::StatusCode::kInvalidArgument);
  }
  for (const std::string token : {"abc", "-5", "12x", " 12", "+3", "0", "99999999999999999999"}) {
    EXPECT_EQ(Db().ListClips({.page_token = token}).status().code(),
              absl::StatusCode::kInvalidArgument)
        << token;
  }
}

TEST_F(StorageTest, ClipsOfOneTopologyShareASkeleton) {
  const std::shared_ptr<const Skeleton> chain = testing::ChainSkeleton();
  const std::shared_ptr<const Skeleton> taller = Rescaled(*chain, 1.3);
  const std::shared_ptr<const Skeleton> other = Renamed(*chain, "tip");
  EXPECT_EQ(*Db().FindSkeleton(*chain), -1);

  const int64_t a = Insert(Named("a"), Motion(chain, 4));
  const int64_t b = Insert(Named("b"), Motion(taller, 4));
  const int64_t c = Insert(Named("c"), Motion(other, 4));
  const int64_t skeleton = Db().GetClipRecord(a)->skeleton_id;
  EXPECT_EQ(Db().GetClipRecord(b)->skeleton_id, skeleton);
  EXPECT_NE(Db().GetClipRecord(c)->skeleton_id, skeleton);
  EXPECT_EQ(*Db().FindSkeleton(*taller), skeleton);
  EXPECT_EQ(*Db().FindSkeleton(*other), Db().GetClipRecord(c)->skeleton_id);
  EXPECT_EQ(CountsNow().skeletons, 2);
  EXPECT_THAT(*Db().ClipsOfSkeleton(skeleton), ::testing::ElementsAre(a, b));

  // Each clip keeps its own offsets.
  ExpectSameLayout(Db().GetClip(a)->clip.skeleton(), *chain);
  ExpectSameLayout(Db().GetClip(b)->clip.skeleton(), *taller);
}

TEST_F(StorageSpaceTest, SpacesAndProjectionsRoundTrip) {
  const int64_t walk = Insert(Named("walk"), walk_);
  const int64_t wave = Insert(Named("wave"), wave_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  const Projection walk_projection = ProjectionOf(walk, walk_);
  const Projection wave_projection = ProjectionOf(wave, wave_);
  const absl::StatusOr<int64_t> space_id =
      Db().InsertSpace(SpaceNamed("body", skeleton), space_, {wave_projection, walk_projection});
  ASSERT_TRUE(space_id.ok()) << space_id.status();

  const absl::StatusOr<SpaceRecord> record = Db().GetSpaceRecord("body");
  ASSERT_TRUE(record.ok()) << record.status();
  EXPECT_EQ(record->space_id, *space_id);
  EXPECT_EQ(record->skeleton_id, skeleton);
  EXPECT_EQ(record->version, 3);
  EXPECT_EQ(record->build_report_json, R"({"dims": 8})");
  EXPECT_GT(record->created_unix_ms, 0);
  const absl::StatusOr<MotionSpace> space = Db().GetSpace(*space_id);
  ASSERT_TRUE(space.ok()) << space.status();
  EXPECT_EQ(SerializeSpace(*space), SerializeSpace(space_));
  ASSERT_EQ(Db().ListSpaces()->size(), 1u);
  EXPECT_EQ(Db().ListSpaces()->front().name, "body");

  // A clip ingested later brings its projection into the skeleton's space.
  const Clip run = testing::SyntheticClip(Rescaled(*skeleton_, 0.9), {.frames = 40, .seed = 3});
  const Projection run_projection = ProjectionOf(0, run);
  const int64_t run_id = Insert(Named("run"), run, {{*space_id, run_projection}});

  const absl::StatusOr<std::vector<Projection>> loaded = Db().LoadProjections(*space_id);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  ASSERT_EQ(loaded->size(), 3u);
  EXPECT_EQ((*loaded)[0].clip_id, walk);
  EXPECT_EQ((*loaded)[0].coordinates, walk_projection.coordinates);
  EXPECT_EQ((*loaded)[1].clip_id, wave);
  EXPECT_EQ((*loaded)[1].coordinates, wave_projection.coordinates);
  EXPECT_EQ((*loaded)[2].clip_id, run_id);
  EXPECT_EQ((*loaded)[2].coordinates, run_projection.coordinates);

  const Counts counts = CountsNow();
  EXPECT_EQ(counts.spaces, 1);
  EXPECT_EQ(counts.projections, 3);
  EXPECT_EQ(counts.frames, 90 + 70 + 40);
}

TEST_F(StorageSpaceTest, EveryClipOfASkeletonHasAProjectionInEachOfItsSpaces) {
  const int64_t walk = Insert(Named("walk"), walk_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  // A space must come with the projections of all its skeleton's clips...
  EXPECT_EQ(Db().InsertSpace(SpaceNamed("body", skeleton), space_, {}).status().code(),
            absl::StatusCode::kFailedPrecondition);
  const int64_t space_id =
      *Db().InsertSpace(SpaceNamed("body", skeleton), space_, {ProjectionOf(walk, walk_)});
  // ... and a clip with its projection into each space of its skeleton.
  const Counts before = CountsNow();
  const absl::StatusOr<int64_t> missing = Db().InsertClip(Named("wave"), wave_, {});
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(missing.status().message(), HasSubstr("'body'"));
  // More columns than the space has dimensions.
  Projection wide = ProjectionOf(0, wave_);
  wide.coordinates = RowMatrixXf::Zero(10, space_.dims() + 1);
  EXPECT_EQ(Db().InsertClip(Named("wave"), wave_, {{space_id, wide}}).status().code(),
            absl::StatusCode::kInvalidArgument);
  // A space of another topology, and a clip of another topology.
  const Clip chain = Motion(testing::ChainSkeleton(), 3);
  EXPECT_EQ(
      Db().InsertClip(Named("chain"), chain, {{space_id, ProjectionOf(0, wave_)}}).status().code(),
      absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  const int64_t chain_id = Insert(Named("chain"), chain);
  EXPECT_EQ(Db().InsertSpace(SpaceNamed("other", skeleton), space_,
                             {ProjectionOf(walk, walk_), ProjectionOf(chain_id, walk_)})
                .status()
                .code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(
      Db().InsertSpace(SpaceNamed("other", Db().GetClipRecord(chain_id)->skeleton_id), space_, {})
          .status()
          .code(),
      absl::StatusCode::kFailedPrecondition);
}

TEST_F(StorageSpaceTest, DeletesCascade) {
  const int64_t walk = Insert(Named("walk", {"a", "b"}), walk_);
  const int64_t wave = Insert(Named("wave", {"a"}), wave_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  const int64_t space_id = *Db().InsertSpace(
      SpaceNamed("body", skeleton), space_, {ProjectionOf(walk, walk_), ProjectionOf(wave, wave_)});
  // Labels written raw, so that the schema's own checks are tried too: a manual label, and one
  // propagated from it in the space onto the other clip.
  std::unique_ptr<SqliteConnection> raw = Raw();
  ASSERT_TRUE(
      raw->Execute(absl::StrCat(
                       "INSERT INTO labels (clip_id, first_frame, last_frame, descriptor, value, "
                       "origin, created_unix_ms) VALUES (",
                       walk,
                       ", 0, 10, 'kick', 1.0, 'manual', 0);"
                       "INSERT INTO labels (clip_id, first_frame, last_frame, descriptor, value, "
                       "origin, source_label_id, space_id, score, job_id, created_unix_ms) "
                       "VALUES (",
                       wave, ", 5, 9, 'kick', 0.7, 'propagated', last_insert_rowid(), ", space_id,
                       ", 0.2, 'job-1', 0)"))
          .ok());
  // The schema refuses values outside [0, 1] and unknown origins.
  EXPECT_FALSE(raw->Execute(absl::StrCat("INSERT INTO labels (clip_id, first_frame, last_frame, "
                                         "descriptor, value, origin, created_unix_ms) VALUES (",
                                         walk, ", 0, 1, 'x', 1.5, 'manual', 0)"))
                   .ok());
  EXPECT_FALSE(raw->Execute(absl::StrCat("INSERT INTO labels (clip_id, first_frame, last_frame, "
                                         "descriptor, value, origin, created_unix_ms) VALUES (",
                                         walk, ", 0, 1, 'x', 0.5, 'guessed', 0)"))
                   .ok());
  raw.reset();
  EXPECT_EQ(CountsNow().labels, 2);

  // Deleting the space keeps the labels found in it, and drops its projections.
  ASSERT_TRUE(Db().DeleteSpace("body").ok());
  Counts counts = CountsNow();
  EXPECT_EQ(counts.spaces, 0);
  EXPECT_EQ(counts.projections, 0);
  EXPECT_EQ(counts.labels, 2);
  EXPECT_EQ(Db().GetSpace(space_id).status().code(), absl::StatusCode::kNotFound);

  // Deleting the labelled clip drops its tags, its label and the label propagated from it.
  ASSERT_TRUE(Db().DeleteClip(walk).ok());
  counts = CountsNow();
  EXPECT_EQ(counts.clips, 1);
  EXPECT_EQ(counts.labels, 0);
  EXPECT_EQ(Db().GetClip(walk).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().ListClips({}, "b")->clips.size(), 0u);
  EXPECT_EQ(Db().ListClips({}, "a")->clips.size(), 1u);

  // Projections go with their clip.
  const int64_t space2 =
      *Db().InsertSpace(SpaceNamed("body2", skeleton), space_, {ProjectionOf(wave, wave_)});
  ASSERT_TRUE(Db().DeleteClip(wave).ok());
  EXPECT_EQ(CountsNow().projections, 0);
  EXPECT_EQ(Db().LoadProjections(space2)->size(), 0u);
  // Ids are not reused.
  EXPECT_GT(Insert(Named("walk"), walk_, {{space2, ProjectionOf(0, walk_)}}), wave);
}

TEST_F(StorageSpaceTest, RejectedWritesChangeNothing) {
  const Clip clip = Motion(testing::ChainSkeleton(), 6);
  const int64_t walk = Insert(Named("walk"), walk_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  ASSERT_TRUE(
      Db().InsertSpace(SpaceNamed("body", skeleton), space_, {ProjectionOf(walk, walk_)}).ok());
  Insert(Named("chain_01"), clip);
  const Counts before = CountsNow();
  Close();
  const std::string file_before = testing::ReadFileOrDie(path_);

  const absl::StatusOr<int64_t> duplicate = Db().InsertClip(Named("chain_01"), clip, {});
  EXPECT_EQ(duplicate.status().code(), absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(duplicate.status().message(), "a clip named 'chain_01' already exists");
  EXPECT_EQ(Db().InsertSpace(SpaceNamed("body", skeleton), space_, {ProjectionOf(walk, walk_)})
                .status()
                .code(),
            absl::StatusCode::kAlreadyExists);

  const absl::StatusOr<StoredClip> missing = Db().GetClip(4242);
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(missing.status().message(), "clip 4242 not found");
  EXPECT_EQ(Db().GetClipRecord(4242).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().DeleteClip(4242).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().DeleteSpace("nope").code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().GetSpaceRecord("nope").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().GetSpace(4242).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().LoadProjections(4242).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().ClipsOfSkeleton(4242).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().InsertSpace(SpaceNamed("new", 4242), space_, {}).status().code(),
            absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().InsertSpace(SpaceNamed("new", skeleton), space_, {ProjectionOf(4242, walk_)})
                .status()
                .code(),
            absl::StatusCode::kNotFound);

  const std::vector<ClipRecord> bad_records = {
      Named(""), Named(std::string(513, 'n')), Named("t", {""}),
      Named("t", {std::string(129, 't')}), Named("t", std::vector<std::string>(65, "x"))};
  for (const ClipRecord& record : bad_records) {
    EXPECT_EQ(Db().InsertClip(record, clip, {}).status().code(), absl::StatusCode::kInvalidArgument)
        << record.name;
  }
  // Beyond float32, and non-finite projections.
  RowMatrixXd far = clip.positions();
  far(0, 0) = 1e300;
  const Clip far_clip =
      *Clip::Create(clip.shared_skeleton(), clip.frame_time(), clip.rotations(), far);
  EXPECT_EQ(Db().InsertClip(Named("far"), far_clip, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  Projection nan = ProjectionOf(walk, walk_);
  nan.coordinates(1, 1) = NAN;
  EXPECT_EQ(Db().InsertSpace(SpaceNamed("nan", skeleton), space_, {nan}).status().code(),
            absl::StatusCode::kInvalidArgument);
  SpaceRecord version0 = SpaceNamed("v0", skeleton);
  version0.version = 0;
  EXPECT_EQ(Db().InsertSpace(version0, space_, {ProjectionOf(walk, walk_)}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(Db().InsertSpace(SpaceNamed("", skeleton), space_, {}).status().code(),
            absl::StatusCode::kInvalidArgument);

  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  Close();
  EXPECT_EQ(testing::ReadFileOrDie(path_), file_before);
}

// A call that ended (deadline, cancellation) before its write committed: every write is rolled
// back whole, the replaced clip of a replacing insert included, and the file is unchanged.
TEST_F(StorageSpaceTest, WritesStoppedBeforeTheCommitChangeNothing) {
  const int64_t walk = Insert(Named("walk", {"a"}), walk_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  ASSERT_TRUE(
      Db().InsertSpace(SpaceNamed("body", skeleton), space_, {ProjectionOf(walk, walk_)}).ok());
  const Counts before = CountsNow();
  Close();
  const std::string file_before = testing::ReadFileOrDie(path_);

  int asked = 0;
  const WriteOptions stop{.should_stop = [&asked] {
    ++asked;
    return true;
  }};
  const std::vector<std::pair<int64_t, Projection>> walk_projection = {
      {Db().GetSpaceRecord("body")->space_id, ProjectionOf(0, walk_)}};
  const std::vector<absl::Status> stopped = {
      Db().InsertClip(Named("walk2"), walk_, walk_projection, {}, stop).status(),
      Db().InsertClip(Named("walk"), walk_, walk_projection, {.replace_clip_id = walk}, stop)
          .status(),
      Db().UpdateClip(walk, {.name = "renamed", .add_tags = {"b"}}, stop).status(),
      Db().DeleteClip(walk, stop),
      Db().InsertSpace(SpaceNamed("body2", skeleton), space_, {ProjectionOf(walk, walk_)}, stop)
          .status(),
      Db().DeleteSpace("body", stop)};
  for (const absl::Status& status : stopped) {
    EXPECT_EQ(status.code(), absl::StatusCode::kCancelled) << status;
    EXPECT_THAT(std::string(status.message()), HasSubstr("nothing was written"));
  }
  EXPECT_EQ(asked, static_cast<int>(stopped.size()));
  // A refused write is refused for its own reason; the stop is asked only of a write that would
  // commit.
  EXPECT_EQ(Db().DeleteClip(4242, stop).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(asked, static_cast<int>(stopped.size()));

  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  EXPECT_EQ(Db().GetClipRecord(walk)->name, "walk");
  Close();
  EXPECT_EQ(testing::ReadFileOrDie(path_), file_before);
  // Not stopped: the same writes commit.
  const WriteOptions go{.should_stop = [] { return false; }};
  EXPECT_TRUE(Db().UpdateClip(walk, {.name = "renamed"}, go).ok());
  EXPECT_TRUE(Db().DeleteSpace("body", go).ok());
}

TEST_F(StorageTest, ClipNamesMayBeRelativePaths) {
  const Clip clip = Motion(testing::ChainSkeleton(), 4);
  const int64_t first = Insert(Named("session1/take_001"), clip);
  const int64_t second = Insert(Named("session2/take_001"), Motion(testing::ChainSkeleton(), 4, 1));
  ASSERT_GT(first, 0);
  ASSERT_GT(second, 0);
  EXPECT_EQ(Db().GetClipRecord(first)->name, "session1/take_001");
  const absl::StatusOr<ClipRecord> by_name = Db().GetClipRecordByName("session2/take_001");
  ASSERT_TRUE(by_name.ok()) << by_name.status();
  EXPECT_EQ(by_name->clip_id, second);
  EXPECT_EQ(Db().GetClipRecordByName("take_001").status().code(), absl::StatusCode::kNotFound);
  // 512 bytes, with segments, dots inside segments and non-ASCII text, is a name.
  const std::string longest = std::string(250, 'a') + "/.hidden/" + std::string(251, 'b') + "é";
  ASSERT_EQ(longest.size(), 512u);
  ClipRecord longest_record = Named(longest);
  longest_record.source_file = "long.bvh";
  EXPECT_GT(Insert(longest_record, clip), 0);
  EXPECT_GT(Insert(Named("a..b/c.d/...x"), clip), 0);
  const absl::StatusOr<int64_t> taken = Db().InsertClip(Named("session1/take_001"), clip, {});
  EXPECT_EQ(taken.status().code(), absl::StatusCode::kAlreadyExists);
}

TEST_F(StorageTest, MalformedNamesAndTagsAreRefused) {
  const Clip clip = Motion(testing::ChainSkeleton(), 4);
  Insert(Named("kept", {"tag"}), clip);
  const Counts before = CountsNow();
  const std::vector<std::string> bad_names = {
      "",
      std::string(513, 'n'),
      std::string("take\0one", 8),
      "take\none",
      "take\tone",
      "take\x7f",
      "take\xc2\x85one",  // NEL, a C1 control character in UTF-8
      "/session1/take_001",
      "session1/take_001/",
      "/",
      "session1//take_001",
      "./take_001",
      "session1/.",
      "session1/../take_001",
      "..",
      "."};
  for (const std::string& name : bad_names) {
    const absl::StatusOr<int64_t> id = Db().InsertClip(Named(name), clip, {});
    EXPECT_EQ(id.status().code(), absl::StatusCode::kInvalidArgument) << absl::CHexEscape(name);
    EXPECT_THAT(id.status().message(), HasSubstr("clip name")) << absl::CHexEscape(name);
    // The message holds no control character of the name.
    EXPECT_EQ(id.status().message().find_first_of(std::string("\0\n\t\x7f", 4)),
              absl::string_view::npos);
  }
  const std::vector<std::string> bad_tags = {std::string("a\0b", 3), "a\nb", "\x1b[31m", ""};
  for (const std::string& tag : bad_tags) {
    const absl::StatusOr<int64_t> id = Db().InsertClip(Named("fresh", {"good", tag}), clip, {});
    EXPECT_EQ(id.status().code(), absl::StatusCode::kInvalidArgument) << absl::CHexEscape(tag);
    EXPECT_THAT(id.status().message(), HasSubstr("tags[1]")) << absl::CHexEscape(tag);
  }
  EXPECT_EQ(Db().ListClips({}, "a\nb").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
}

TEST_F(StorageTest, ContentHashIsOfTheStoredMotion) {
  const std::shared_ptr<const Skeleton> chain = testing::ChainSkeleton();
  const Clip walk = Motion(chain, 40, 1);
  const int64_t a = Insert(Named("walk"), walk);
  const int64_t b = Insert(Named("session2/walk"), walk);
  const std::string hash = Db().GetClipRecord(a)->content_hash;
  EXPECT_THAT(hash, ::testing::MatchesRegex("[0-9a-f]{64}"));
  EXPECT_EQ(Db().GetClipRecord(b)->content_hash, hash);
  EXPECT_EQ(Db().GetClip(a)->record.content_hash, hash);
  EXPECT_EQ(Db().ListClips({})->clips[1].content_hash, hash);
  // What the catalogue computes before an insert, to recognise a file stored before.
  EXPECT_EQ(*ContentHash(walk), hash);

  // Digits beyond float32 are formatting, not motion.
  RowMatrixXd nudged = walk.positions();
  nudged(3, 1) += 1e-12;
  EXPECT_EQ(*ContentHash(
                *Clip::Create(walk.shared_skeleton(), walk.frame_time(), walk.rotations(), nudged)),
            hash);
  // Any other frame, rate or skeleton layout is another content.
  RowMatrixXd moved = walk.positions();
  moved(3, 1) += 0.5;
  const Clip one_frame_moved =
      *Clip::Create(walk.shared_skeleton(), walk.frame_time(), walk.rotations(), moved);
  const Clip other_rate =
      *Clip::Create(walk.shared_skeleton(), 1.0 / 60, walk.rotations(), walk.positions());
  const Clip other_actor =
      *Clip::Create(Rescaled(*chain, 1.2), walk.frame_time(), walk.rotations(), walk.positions());
  std::set<std::string> hashes = {hash};
  for (const Clip& other :
       {one_frame_moved, other_rate, other_actor, Motion(chain, 40, 2), Motion(chain, 39, 1)}) {
    const int64_t id = Insert(Named(absl::StrCat("other_", hashes.size())), other);
    const std::string other_hash = Db().GetClipRecord(id)->content_hash;
    EXPECT_EQ(*ContentHash(other), other_hash);
    EXPECT_TRUE(hashes.insert(other_hash).second) << "clip " << id << " hashes as another";
  }

  const absl::StatusOr<std::vector<ClipRecord>> same = Db().FindClipsByContentHash(hash, 10);
  ASSERT_TRUE(same.ok()) << same.status();
  ASSERT_EQ(same->size(), 2u);
  EXPECT_EQ((*same)[0].clip_id, a);
  EXPECT_EQ((*same)[1].name, "session2/walk");
  EXPECT_EQ(Db().FindClipsByContentHash(hash, 1)->size(), 1u);
  EXPECT_TRUE(Db().FindClipsByContentHash(std::string(64, '0'), 10)->empty());
}

TEST_F(StorageSpaceTest, ReplaceSwapsTheClipInOneTransaction) {
  const int64_t walk = Insert(Named("take_001", {"old"}), walk_);
  const int64_t other = Insert(Named("take_002"), wave_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  const int64_t space_id =
      *Db().InsertSpace(SpaceNamed("body", skeleton), space_,
                        {ProjectionOf(walk, walk_), ProjectionOf(other, wave_)});
  ASSERT_TRUE(Raw()
                  ->Execute(absl::StrCat("INSERT INTO labels (clip_id, first_frame, last_frame, "
                                         "descriptor, value, origin, created_unix_ms) VALUES (",
                                         walk, ", 0, 10, 'kick', 1.0, 'manual', 0)"))
                  .ok());
  const Counts before = CountsNow();
  const std::string old_hash = Db().GetClipRecord(walk)->content_hash;
  const Clip run = testing::SyntheticClip(skeleton_, {.frames = 50, .seed = 5});

  // A replace whose insert fails after the delete leaves the old clip, its label and projection.
  Projection projection;
  projection.coordinates = RowMatrixXf::Ones(3, 2);
  EXPECT_EQ(Db().InsertClip(Named("take_001"), run, {{999, projection}}, {.replace_clip_id = walk})
                .status()
                .code(),
            absl::StatusCode::kNotFound);
  // So does one whose name belongs to a clip other than the replaced one.
  EXPECT_EQ(Db().InsertClip(Named("take_002"), run, {{space_id, ProjectionOf(0, run)}},
                            {.replace_clip_id = walk})
                .status()
                .code(),
            absl::StatusCode::kAlreadyExists);
  const absl::StatusOr<int64_t> unknown = Db().InsertClip(
      Named("take_009"), run, {{space_id, ProjectionOf(0, run)}}, {.replace_clip_id = 4242});
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(unknown.status().message(), HasSubstr("4242"));
  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  EXPECT_EQ(Db().GetClipRecord(walk)->content_hash, old_hash);

  const Projection run_projection = ProjectionOf(0, run);
  const absl::StatusOr<int64_t> replaced = Db().InsertClip(
      Named("take_001", {"new"}), run, {{space_id, run_projection}}, {.replace_clip_id = walk});
  ASSERT_TRUE(replaced.ok()) << replaced.status();
  EXPECT_GT(*replaced, other);
  EXPECT_EQ(Db().GetClip(walk).status().code(), absl::StatusCode::kNotFound);
  const absl::StatusOr<ClipRecord> now = Db().GetClipRecordByName("take_001");
  ASSERT_TRUE(now.ok()) << now.status();
  EXPECT_EQ(now->clip_id, *replaced);
  EXPECT_EQ(now->frame_count, 50);
  EXPECT_THAT(now->tags, ::testing::ElementsAre("new"));
  EXPECT_NE(now->content_hash, old_hash);
  EXPECT_TRUE(Db().FindClipsByContentHash(old_hash, 10)->empty());
  const Counts after = CountsNow();
  EXPECT_EQ(after.clips, before.clips);
  EXPECT_EQ(after.projections, before.projections);
  EXPECT_EQ(after.labels, 0);  // the old clip's label went with it
  const std::vector<Projection> loaded = *Db().LoadProjections(space_id);
  ASSERT_EQ(loaded.size(), 2u);
  EXPECT_EQ(loaded[0].clip_id, other);
  EXPECT_EQ(loaded[1].clip_id, *replaced);
  EXPECT_EQ(loaded[1].coordinates, run_projection.coordinates);
}

ClipUpdate Update(std::optional<std::string> name, std::vector<std::string> add_tags = {},
                  std::vector<std::string> remove_tags = {}) {
  ClipUpdate update;
  update.name = std::move(name);
  update.add_tags = std::move(add_tags);
  update.remove_tags = std::move(remove_tags);
  return update;
}

TEST_F(StorageTest, UpdateClipRenamesAndRetagsAtomically) {
  const Clip clip = Motion(testing::ChainSkeleton(), 4);
  const int64_t walk = Insert(Named("take_001", {"draft", "walk"}), clip);
  Insert(Named("session2/take_001"), clip);

  const ClipUpdate update =
      Update("session1/take_001", {"session1", "walk", "final", "final"}, {"draft", "never-there"});
  const absl::StatusOr<ClipRecord> updated = Db().UpdateClip(walk, update);
  ASSERT_TRUE(updated.ok()) << updated.status();
  EXPECT_EQ(updated->clip_id, walk);
  EXPECT_EQ(updated->name, "session1/take_001");
  EXPECT_THAT(updated->tags, ::testing::ElementsAre("final", "session1", "walk"));
  const ClipRecord stored = *Db().GetClipRecord(walk);
  EXPECT_EQ(stored.name, "session1/take_001");
  EXPECT_EQ(stored.tags, updated->tags);
  EXPECT_EQ(stored.content_hash, updated->content_hash);
  EXPECT_EQ(Db().ListClips({}, "draft")->clips.size(), 0u);
  EXPECT_EQ(Db().ListClips({}, "final")->clips.size(), 1u);
  EXPECT_EQ(Db().GetClipRecordByName("take_001").status().code(), absl::StatusCode::kNotFound);
  // The old name is free again; its own name is no conflict; nothing set changes nothing.
  EXPECT_GT(Insert(Named("take_001"), clip), 0);
  EXPECT_TRUE(Db().UpdateClip(walk, Update("session1/take_001")).ok());
  EXPECT_EQ(Db().UpdateClip(walk, Update(std::nullopt))->tags, updated->tags);

  const Counts counts = CountsNow();
  struct Bad {
    ClipUpdate update;
    absl::StatusCode code;
    std::string words;
  };
  std::vector<std::string> many;  // 62 new tags beside the 3 carried: over 64 only in the end
  for (int i = 0; i < 62; ++i) many.push_back(absl::StrCat("t", i));
  const std::vector<Bad> bad = {
      {Update("session2/take_001"), absl::StatusCode::kAlreadyExists, "session2/take_001"},
      {Update("a//b"), absl::StatusCode::kInvalidArgument, "clip name"},
      {Update(""), absl::StatusCode::kInvalidArgument, "clip name"},
      {Update("x", {"ok", "bad\n"}), absl::StatusCode::kInvalidArgument, "add_tags[1]"},
      {Update(std::nullopt, {"ok"}, {""}), absl::StatusCode::kInvalidArgument, "remove_tags[0]"},
      {Update(std::nullopt, {"ok"}, {"ok"}), absl::StatusCode::kInvalidArgument, "add_tags"},
      // Refused after the rename has run, which rolls back with it.
      {Update("renamed", many), absl::StatusCode::kInvalidArgument, "at most 64"},
  };
  for (const Bad& b : bad) {
    const absl::StatusOr<ClipRecord> refused = Db().UpdateClip(walk, b.update);
    EXPECT_EQ(refused.status().code(), b.code) << b.words << ": " << refused.status();
    EXPECT_THAT(refused.status().message(), HasSubstr(b.words));
  }
  EXPECT_EQ(Db().UpdateClip(4242, Update("x")).status().code(), absl::StatusCode::kNotFound);
  const ClipRecord unchanged = *Db().GetClipRecord(walk);
  EXPECT_EQ(unchanged.name, "session1/take_001");
  EXPECT_EQ(unchanged.tags, updated->tags);
  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(counts));
}

TEST_F(StorageTest, FailureMidTransactionLeavesNoRow) {
  const Counts before = CountsNow();
  Projection projection;
  projection.coordinates = RowMatrixXf::Ones(3, 2);
  // The clip row, its skeleton and tags are written before the projection's space is found
  // missing; all of it rolls back.
  const absl::StatusOr<int64_t> id = Db().InsertClip(
      Named("walk", {"a"}), Motion(testing::ChainSkeleton(), 3), {{999, projection}});
  EXPECT_EQ(id.status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(id.status().message(), "space 999 not found");
  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  EXPECT_EQ(Db().ListClips({})->clips.size(), 0u);
  EXPECT_EQ(*Db().FindSkeleton(*testing::ChainSkeleton()), -1);
  EXPECT_GT(Insert(Named("walk"), Motion(testing::ChainSkeleton(), 3)), 0);
}

TEST_F(StorageSpaceTest, ReopenKeepsEverything) {
  const int64_t walk = Insert(Named("walk", {"x"}), walk_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  const Projection projection = ProjectionOf(walk, walk_);
  const int64_t space_id = *Db().InsertSpace(SpaceNamed("body", skeleton), space_, {projection});
  const Counts before = CountsNow();
  Close();
  EXPECT_FALSE(std::filesystem::exists(path_ + "-wal"));  // checkpointed on close

  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  const absl::StatusOr<StoredClip> stored = Db().GetClip(walk);
  ASSERT_TRUE(stored.ok()) << stored.status();
  ExpectSameFrames(walk_, stored->clip);
  EXPECT_THAT(stored->record.tags, ::testing::ElementsAre("x"));
  EXPECT_EQ(SerializeSpace(*Db().GetSpace(space_id)), SerializeSpace(space_));
  EXPECT_EQ(Db().LoadProjections(space_id)->front().coordinates, projection.coordinates);
  EXPECT_EQ(*Raw()->QueryInt64("PRAGMA user_version"), LatestSchemaVersion());
}

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

// ---------------------------------------------------------------------------------------------
// Labels.

LabelRecord Manual(int64_t clip_id, int64_t first, int64_t last, const std::string& descriptor,
                   double value) {
  LabelRecord label;
  label.clip_id = clip_id;
  label.first_frame = first;
  label.last_frame = last;
  label.descriptor = descriptor;
  label.value = value;
  return label;
}

std::vector<int64_t> IdsOf(const std::vector<LabelRecord>& labels) {
  std::vector<int64_t> ids;
  for (const LabelRecord& label : labels) ids.push_back(label.label_id);
  return ids;
}

// The ids of a batch AddLabels stored, in its order.
absl::StatusOr<std::vector<int64_t>> IdsOf(const absl::StatusOr<AddedLabels>& added) {
  if (!added.ok()) return added.status();
  return IdsOf(added->labels);
}

TEST_F(StorageTest, ListClipsFiltersBySkeletonAndDescriptorAndCountsTheMatches) {
  const int64_t chain_a = Insert(Named("chain_a", {"t"}), Motion(testing::ChainSkeleton(), 20, 1));
  const int64_t humanoid =
      Insert(Named("humanoid", {"t"}), Motion(testing::HumanoidSkeleton(true), 20, 2));
  const int64_t chain_b = Insert(Named("chain_b"), Motion(testing::ChainSkeleton(), 20, 3));
  const int64_t chain_skeleton = Db().GetClipRecord(chain_a)->skeleton_id;
  const int64_t humanoid_skeleton = Db().GetClipRecord(humanoid)->skeleton_id;
  ASSERT_NE(chain_skeleton, humanoid_skeleton);
  // Two labels of one descriptor on one clip count it once.
  ASSERT_TRUE(
      Db().AddLabels({Manual(chain_b, 0, 4, "kick", 1), Manual(chain_b, 10, 14, "kick", 1),
                      Manual(humanoid, 0, 4, "kick", 0.5), Manual(chain_a, 0, 4, "wave", 1)})
          .ok());
  const auto listed = [&](const ClipFilter& filter, int page_size = 100) {
    const absl::StatusOr<ClipPage> page = Db().ListClips(Sized(page_size), filter);
    EXPECT_TRUE(page.ok()) << page.status();
    std::vector<int64_t> ids;
    for (const ClipRecord& record : page.value_or(ClipPage{}).clips) ids.push_back(record.clip_id);
    return std::make_pair(ids, page.ok() ? page->total_size : -1);
  };
  using Ids = std::vector<int64_t>;
  EXPECT_EQ(listed({}), std::make_pair(Ids{chain_a, humanoid, chain_b}, int64_t{3}));
  EXPECT_EQ(listed({.skeleton_id = chain_skeleton}),
            std::make_pair(Ids{chain_a, chain_b}, int64_t{2}));
  EXPECT_EQ(listed({.skeleton_id = humanoid_skeleton}), std::make_pair(Ids{humanoid}, int64_t{1}));
  EXPECT_EQ(listed({.descriptor = "kick"}), std::make_pair(Ids{humanoid, chain_b}, int64_t{2}));
  EXPECT_EQ(listed({.skeleton_id = chain_skeleton, .descriptor = "kick"}),
            std::make_pair(Ids{chain_b}, int64_t{1}));
  EXPECT_EQ(listed({.tag = "t", .descriptor = "wave"}), std::make_pair(Ids{chain_a}, int64_t{1}));
  EXPECT_EQ(listed({.descriptor = "jump"}), std::make_pair(Ids{}, int64_t{0}));
  EXPECT_EQ(listed({.skeleton_id = 999}), std::make_pair(Ids{}, int64_t{0}));
  // The total counts every page's clips, whatever the page holds; names in name order too.
  EXPECT_EQ(listed({}, 1), std::make_pair(Ids{chain_a}, int64_t{3}));
  EXPECT_EQ(listed({.name_contains = "chain", .order = ClipOrder::kName}, 1),
            std::make_pair(Ids{chain_a}, int64_t{2}));

  EXPECT_EQ(Db().ListClips({}, ClipFilter{.skeleton_id = -1}).status().code(),
            absl::StatusCode::kInvalidArgument);
  const absl::Status bad_descriptor = Db().ListClips({}, ClipFilter{.descriptor = "a\nb"}).status();
  EXPECT_EQ(bad_descriptor.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad_descriptor.message(), ::testing::HasSubstr("descriptor"));
}

TEST_F(StorageTest, LabelsAreListedFoundAndTimelinedAndPagedOnce) {
  const int64_t walk = Insert(Named("walk", {"gait"}), Motion(testing::ChainSkeleton(), 50, 1));
  const int64_t kick = Insert(Named("kick", {"fight"}), Motion(testing::ChainSkeleton(), 30, 2));
  const absl::StatusOr<std::vector<int64_t>> ids = IdsOf(Db().AddLabels({
      Manual(walk, 20, 29, "step", 0.5),  // ids[0]
      Manual(kick, 0, 9, "step", 0.9),    // ids[1]
      Manual(walk, 0, 9, "step", 0.9),    // ids[2]
      Manual(walk, 5, 49, "walk", 1),     // ids[3]
      Manual(kick, 10, 29, "kick", 1),    // ids[4]
  }));
  ASSERT_TRUE(ids.ok()) << ids.status();
  ASSERT_EQ(ids->size(), 5u);
  EXPECT_TRUE(std::is_sorted(ids->begin(), ids->end()));
  EXPECT_EQ(CountsNow().labels, 5);

  // Listed in id order, with the clip's name and rate, filtered.
  absl::StatusOr<LabelPage> all = Db().ListLabels({}, {});
  ASSERT_TRUE(all.ok()) << all.status();
  EXPECT_EQ(IdsOf(all->labels), *ids);
  EXPECT_TRUE(all->next_page_token.empty());
  const LabelRecord& first = all->labels[0];
  EXPECT_EQ(first.clip_name, "walk");
  EXPECT_DOUBLE_EQ(first.frame_time, 1.0 / 120.0);
  EXPECT_EQ(first.first_frame, 20);
  EXPECT_EQ(first.last_frame, 29);
  EXPECT_EQ(first.origin, LabelOrigin::kManual);
  EXPECT_GT(first.created_unix_ms, 0);
  EXPECT_EQ(IdsOf(Db().ListLabels({}, {.clip_id = kick})->labels),
            (std::vector<int64_t>{(*ids)[1], (*ids)[4]}));
  EXPECT_EQ(IdsOf(Db().ListLabels({}, {.descriptor = "step", .min_value = 0.6})->labels),
            (std::vector<int64_t>{(*ids)[1], (*ids)[2]}));
  EXPECT_TRUE(Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels.empty());

  // Pages of two visit every label once.
  std::vector<int64_t> paged;
  Page page = Sized(2);
  do {
    const absl::StatusOr<LabelPage> next = Db().ListLabels(page, {});
    ASSERT_TRUE(next.ok()) << next.status();
    ASSERT_LE(next->labels.size(), 2u);
    for (const LabelRecord& label : next->labels) paged.push_back(label.label_id);
    page.page_token = next->next_page_token;
  } while (!page.page_token.empty());
  EXPECT_EQ(paged, *ids);

  // Found strongest first, then by clip and first frame; a page at a time; by tag.
  const std::vector<int64_t> strongest = {(*ids)[2], (*ids)[1], (*ids)[0]};
  EXPECT_EQ(IdsOf(Db().FindLabels({}, {.descriptor = "step"})->labels), strongest);
  paged.clear();
  page = Sized(1);
  do {
    const absl::StatusOr<LabelPage> next = Db().FindLabels(page, {.descriptor = "step"});
    ASSERT_TRUE(next.ok()) << next.status();
    for (const LabelRecord& label : next->labels) paged.push_back(label.label_id);
    page.page_token = next->next_page_token;
  } while (!page.page_token.empty());
  EXPECT_EQ(paged, strongest);
  EXPECT_EQ(IdsOf(Db().FindLabels({}, {.descriptor = "step", .min_value = 0.9})->labels),
            (std::vector<int64_t>{(*ids)[2], (*ids)[1]}));
  EXPECT_EQ(IdsOf(Db().FindLabels({}, {.descriptor = "step", .tags = {"fight", "none"}})->labels),
            (std::vector<int64_t>{(*ids)[1]}));
  EXPECT_TRUE(Db().FindLabels({}, {.descriptor = "jump"})->labels.empty());

  // A clip's timeline, by first frame, a page at a time.
  const absl::StatusOr<LabelPage> timeline = Db().ClipLabels(walk, {});
  ASSERT_TRUE(timeline.ok()) << timeline.status();
  EXPECT_EQ(IdsOf(timeline->labels), (std::vector<int64_t>{(*ids)[2], (*ids)[3], (*ids)[0]}));
  EXPECT_TRUE(timeline->next_page_token.empty());
  std::vector<int64_t> timeline_pages;
  Page timeline_page{.page_size = 2, .page_token = ""};
  do {
    const absl::StatusOr<LabelPage> next = Db().ClipLabels(walk, timeline_page);
    ASSERT_TRUE(next.ok()) << next.status();
    for (const LabelRecord& label : next->labels) timeline_pages.push_back(label.label_id);
    timeline_page.page_token = next->next_page_token;
  } while (!timeline_page.page_token.empty());
  EXPECT_EQ(timeline_pages, IdsOf(timeline->labels));
  EXPECT_EQ(Db().ClipLabels(4242, {}).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().ClipLabels(walk, {.page_token = "f:1:2:3:4"}).status().code(),
            absl::StatusCode::kInvalidArgument);

  // Tokens of another listing, and bad queries, are refused.
  EXPECT_EQ(Db().FindLabels({.page_token = "7"}, {.descriptor = "step"}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(Db().ListLabels({.page_token = "f:1:2:3:4"}, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(Db().FindLabels({}, {.descriptor = ""}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(Db().FindLabels({}, {.descriptor = "step", .min_value = 1.5}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(Db().ListLabels({}, {.min_value = NAN}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// FindLabels pages of one and of two across ties: labels of one value and clip told apart by
// first frame, and of one first frame told apart by id, each visited once in order.
TEST_F(StorageTest, FindLabelsPagesAcrossTies) {
  const int64_t walk = Insert(Named("walk"), Motion(testing::ChainSkeleton(), 50, 1));
  const int64_t kick = Insert(Named("kick"), Motion(testing::ChainSkeleton(), 30, 2));
  const absl::StatusOr<std::vector<int64_t>> ids = IdsOf(Db().AddLabels({
      Manual(walk, 20, 29, "step", 0.5),  // ids[0]
      Manual(walk, 10, 19, "step", 0.5),  // ids[1]
      Manual(walk, 10, 12, "step", 0.5),  // ids[2]: ids[1]'s first frame
      Manual(kick, 0, 9, "step", 0.5),    // ids[3]
      Manual(walk, 10, 30, "step", 0.5),  // ids[4]: ids[1]'s first frame again
      Manual(walk, 0, 5, "step", 0.9),    // ids[5]
  }));
  ASSERT_TRUE(ids.ok()) << ids.status();
  const std::vector<int64_t> order = {(*ids)[5], (*ids)[1], (*ids)[2],
                                      (*ids)[4], (*ids)[0], (*ids)[3]};
  ASSERT_LT(walk, kick);
  EXPECT_EQ(IdsOf(Db().FindLabels({}, {.descriptor = "step"})->labels), order);
  for (const int size : {1, 2, 3, 4}) {
    std::vector<int64_t> paged;
    Page page = Sized(size);
    do {
      const absl::StatusOr<LabelPage> next = Db().FindLabels(page, {.descriptor = "step"});
      ASSERT_TRUE(next.ok()) << next.status();
      ASSERT_LE(next->labels.size(), static_cast<size_t>(size));
      for (const LabelRecord& label : next->labels) paged.push_back(label.label_id);
      page.page_token = next->next_page_token;
    } while (!page.page_token.empty());
    EXPECT_EQ(paged, order) << "pages of " << size;
  }
}

// Tags of a query are a set of at most kMaxTags; a token's value is a label's, in [0, 1];
// filters and timelines of an unknown clip are NOT_FOUND naming clip_id.
TEST_F(StorageTest, LabelQueriesRefuseTooManyTagsForgedTokensAndUnknownClips) {
  const int64_t walk = Insert(Named("walk", {"gait"}), Motion(testing::ChainSkeleton(), 50, 1));
  ASSERT_TRUE(Db().AddLabels({Manual(walk, 0, 9, "step", 0.5)}).ok());

  std::vector<std::string> tags(64, "gait");
  EXPECT_EQ(Db().FindLabels({}, {.descriptor = "step", .tags = tags})->labels.size(), 1u);
  tags.push_back("gait");
  const absl::Status too_many = Db().FindLabels({}, {.descriptor = "step", .tags = tags}).status();
  EXPECT_EQ(too_many.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(too_many.message()), HasSubstr("tags: at most 64"));
  EXPECT_EQ(Db().FindLabels({}, {.descriptor = "step", .tags = {"gait", ""}}).status().code(),
            absl::StatusCode::kInvalidArgument);

  for (const std::string token : {"f:nan:1:0:1", "f:inf:1:0:1", "f:-inf:1:0:1", "f:1.5:1:0:1",
                                  "f:-0.5:1:0:1", "f:NaN:1:0:1"}) {
    const absl::Status forged =
        Db().FindLabels({.page_token = token}, {.descriptor = "step"}).status();
    EXPECT_EQ(forged.code(), absl::StatusCode::kInvalidArgument) << token;
    EXPECT_THAT(std::string(forged.message()), HasSubstr("malformed page_token")) << token;
  }
  EXPECT_TRUE(Db().FindLabels({.page_token = "f:1:1:0:0"}, {.descriptor = "step"}).ok());

  const auto names_clip = [](const absl::Status& status) {
    EXPECT_EQ(status.code(), absl::StatusCode::kNotFound);
    EXPECT_EQ(status.message(), "clip_id: clip 4242 not found");
  };
  names_clip(Db().ListLabels({}, {.clip_id = 4242}).status());
  names_clip(Db().DeleteLabels(LabelFilter{.clip_id = 4242}).status());
  names_clip(Db().ClipLabels(4242, {}).status());
  EXPECT_EQ(CountsNow().labels, 1);
}

// Each bad label fails the whole batch with the item and field named, and nothing is stored.
TEST_F(StorageTest, LabelBatchesAreAllOrNothing) {
  const int64_t walk = Insert(Named("walk"), Motion(testing::ChainSkeleton(), 50, 1));
  // The longest descriptor, the range's ends and the value's are allowed.
  ASSERT_TRUE(
      Db().AddLabels({Manual(walk, 0, 9, "step", 1), Manual(walk, 0, 49, std::string(256, 'd'), 0)})
          .ok());
  const Counts before = CountsNow();
  Close();
  const std::string file_before = testing::ReadFileOrDie(path_);

  LabelRecord propagated_without_source = Manual(walk, 0, 1, "x", 1);
  propagated_without_source.origin = LabelOrigin::kPropagated;
  LabelRecord manual_with_score = Manual(walk, 0, 1, "x", 1);
  manual_with_score.score = 0.3;
  LabelRecord unknown_source = propagated_without_source;
  unknown_source.source_label_id = 4242;
  const struct {
    LabelRecord bad;
    absl::StatusCode code;
    std::string message;
  } cases[] = {
      {Manual(4242, 0, 1, "x", 1), absl::StatusCode::kNotFound,
       "labels[1].clip_id: clip 4242 not found"},
      {Manual(walk, 40, 50, "x", 1), absl::StatusCode::kInvalidArgument,
       "labels[1].last_frame: 50 is outside the clip's frames 0..49"},
      {Manual(walk, 9, 8, "x", 1), absl::StatusCode::kInvalidArgument,
       "labels[1].last_frame: 8 is before first_frame 9"},
      {Manual(walk, -1, 8, "x", 1), absl::StatusCode::kInvalidArgument,
       "labels[1].first_frame: -1 is negative"},
      {Manual(walk, 0, 1, "x", 1.5), absl::StatusCode::kInvalidArgument,
       "labels[1].value: 1.5 is outside [0, 1]"},
      {Manual(walk, 0, 1, "x", -0.1), absl::StatusCode::kInvalidArgument,
       "labels[1].value: -0.1 is outside [0, 1]"},
      {Manual(walk, 0, 1, "x", NAN), absl::StatusCode::kInvalidArgument,
       "labels[1].value: nan is outside [0, 1]"},
      {Manual(walk, 0, 1, "", 1), absl::StatusCode::kInvalidArgument,
       "labels[1].descriptor must not be empty"},
      {Manual(walk, 0, 1, std::string(257, 'd'), 1), absl::StatusCode::kInvalidArgument,
       "labels[1].descriptor is 257 bytes long, at most 256"},
      {Manual(walk, 0, 1, "a\tb", 1), absl::StatusCode::kInvalidArgument,
       "labels[1].descriptor 'a\\tb' holds a control character"},
      {propagated_without_source, absl::StatusCode::kInvalidArgument, "labels[1].source_label_id"},
      {manual_with_score, absl::StatusCode::kInvalidArgument, "labels[1]: a manual label"},
      {unknown_source, absl::StatusCode::kNotFound,
       "labels[1].source_label_id: label 4242 not found"},
  };
  for (const auto& c : cases) {
    // A good label first, which must not be stored either.
    const absl::StatusOr<AddedLabels> added =
        Db().AddLabels({Manual(walk, 10, 19, "good", 1), c.bad, Manual(walk, 0, 49, "ok", 1)});
    EXPECT_EQ(added.status().code(), c.code) << c.message;
    EXPECT_THAT(std::string(added.status().message()), HasSubstr(c.message));
  }
  EXPECT_EQ(Db().AddLabels({}).status().code(), absl::StatusCode::kInvalidArgument);

  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  Close();
  EXPECT_EQ(testing::ReadFileOrDie(path_), file_before);
}

StorageSpaceTest::LabelledLibrary StorageSpaceTest::InsertLabelledLibrary() {
  LabelledLibrary library;
  library.walk = Insert(Named("walk"), walk_);
  library.wave = Insert(Named("wave"), wave_);
  const int64_t skeleton = Db().GetClipRecord(library.walk)->skeleton_id;
  library.space_id =
      *Db().InsertSpace(SpaceNamed("body", skeleton), space_,
                        {ProjectionOf(library.walk, walk_), ProjectionOf(library.wave, wave_)});
  library.manual = *IdsOf(Db().AddLabels(
      {Manual(library.walk, 0, 9, "kick", 1), Manual(library.walk, 20, 29, "wave", 0.8)}));
  return library;
}

// Deletes by id and by filter; a manual label takes those propagated from it, a clip its
// labels; a stopped write changes nothing.
TEST_F(StorageSpaceTest, LabelDeletesCascadeAndStoppedLabelWritesChangeNothing) {
  const auto [walk, wave, space_id, manual] = InsertLabelledLibrary();
  LabelRecord found = Manual(wave, 5, 15, "kick", 0.7);
  found.origin = LabelOrigin::kPropagated;
  found.source_label_id = manual[0];
  found.space_id = space_id;
  found.score = 0.25;
  found.job_id = "job-1";
  const int64_t propagated = Db().AddLabels({found})->labels.front().label_id;
  const absl::StatusOr<LabelPage> listed =
      Db().ListLabels({}, {.origin = LabelOrigin::kPropagated});
  ASSERT_EQ(listed->labels.size(), 1u);
  EXPECT_EQ(listed->labels[0].label_id, propagated);
  EXPECT_EQ(listed->labels[0].source_label_id, manual[0]);
  EXPECT_EQ(listed->labels[0].space_name, "body");
  EXPECT_DOUBLE_EQ(listed->labels[0].score, 0.25);
  EXPECT_EQ(listed->labels[0].job_id, "job-1");

  // Stopped before the commit: nothing changes.
  const WriteOptions stop{.should_stop = [] { return true; }};
  EXPECT_EQ(Db().AddLabels({Manual(walk, 0, 1, "x", 1)}, stop).status().code(),
            absl::StatusCode::kCancelled);
  EXPECT_EQ(Db().DeleteLabels(manual, stop).status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(Db().DeleteLabels(LabelFilter{.clip_id = walk}, stop).status().code(),
            absl::StatusCode::kCancelled);
  EXPECT_EQ(CountsNow().labels, 3);

  // An unknown id: NOT_FOUND naming it, and nothing deleted; an empty filter is refused.
  const absl::StatusOr<int64_t> unknown = Db().DeleteLabels(std::vector<int64_t>{manual[1], 4242});
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(unknown.status().message()), HasSubstr("label_ids[1]: label 4242"));
  EXPECT_EQ(Db().DeleteLabels(LabelFilter{}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CountsNow().labels, 3);

  // Deleting the space keeps the label found in it, without the space.
  ASSERT_TRUE(Db().DeleteSpace("body").ok());
  EXPECT_EQ(Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels[0].space_id, 0);
  // The manual label and the one propagated from it (named too) go together.
  EXPECT_EQ(*Db().DeleteLabels(std::vector<int64_t>{manual[0], propagated, manual[0]}), 2);
  EXPECT_EQ(IdsOf(Db().ListLabels({}, {})->labels), (std::vector<int64_t>{manual[1]}));
  // By filter: how many the filter took.
  ASSERT_TRUE(Db().AddLabels({Manual(wave, 0, 9, "wave", 1)}).ok());
  EXPECT_EQ(*Db().DeleteLabels(LabelFilter{.clip_id = walk, .descriptor = "kick"}), 0);
  EXPECT_EQ(*Db().DeleteLabels(LabelFilter{.descriptor = "wave", .min_value = 0.9}), 1);
  // A clip takes its labels with it.
  ASSERT_TRUE(Db().DeleteClip(walk).ok());
  EXPECT_EQ(CountsNow().labels, 0);
}

// ---------------------------------------------------------------------------------------------
// Jobs.

TEST_F(StorageTest, JobsAreCreatedUpdatedListedNewestFirstAndPaged) {
  JobRecord job;
  job.parameters_json = R"({"space":"body"})";
  const absl::StatusOr<JobRecord> first = Db().CreateJob(job);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(first->job_id, "job-1");
  EXPECT_EQ(first->state, JobState::kQueued);
  EXPECT_GT(first->created_unix_ms, 0);
  const JobRecord second = *Db().CreateJob(job);
  const JobRecord third = *Db().CreateJob(job);
  EXPECT_EQ(third.job_id, "job-3");

  JobRecord running = *first;
  running.state = JobState::kRunning;
  running.started_unix_ms = 1700000000000;
  running.done = 3;
  running.total = 10;
  running.queries = 3;
  running.queries_skipped = 1;
  ASSERT_TRUE(Db().UpdateJob(running).ok());
  const absl::StatusOr<JobRecord> read = Db().GetJob("job-1");
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->state, JobState::kRunning);
  EXPECT_EQ(read->parameters_json, job.parameters_json);
  EXPECT_EQ(read->done, 3);
  EXPECT_EQ(read->total, 10);
  EXPECT_EQ(read->queries_skipped, 1);
  EXPECT_EQ(read->started_unix_ms, 1700000000000);

  // Newest first, a page at a time, each job once.
  std::vector<std::string> listed;
  Page page{.page_size = 2, .page_token = ""};
  do {
    const absl::StatusOr<JobPage> jobs = Db().ListJobs(page);
    ASSERT_TRUE(jobs.ok()) << jobs.status();
    for (const JobRecord& listed_job : jobs->jobs) listed.push_back(listed_job.job_id);
    page.page_token = jobs->next_page_token;
  } while (!page.page_token.empty());
  EXPECT_EQ(listed, (std::vector<std::string>{third.job_id, second.job_id, "job-1"}));

  // Unknown or malformed ids, a bad page token, a bad kind or a final state.
  for (const std::string id : {"job-99", "job-0", "7", "job-x", ""}) {
    EXPECT_EQ(Db().GetJob(id).status().code(), absl::StatusCode::kNotFound) << id;
  }
  running.job_id = "job-99";
  EXPECT_EQ(Db().UpdateJob(running).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().ListJobs({.page_token = "x"}).status().code(), absl::StatusCode::kInvalidArgument);
  job.kind = "build";
  EXPECT_EQ(Db().CreateJob(job).status().code(), absl::StatusCode::kInvalidArgument);
  job.kind = "propagation";
  job.state = JobState::kSucceeded;
  EXPECT_EQ(Db().CreateJob(job).status().code(), absl::StatusCode::kInvalidArgument);
}

// A database opened with jobs still queued or running was left by a process that died (or
// stopped) first: those jobs are interrupted, the finished ones stay as they were.
TEST_F(StorageTest, JobsAreCountedByState) {
  EXPECT_TRUE(Db().CountJobs()->empty());
  JobRecord job;
  const JobRecord first = *Db().CreateJob(job);
  Db().CreateJob(job).IgnoreError();
  JobRecord failed = *Db().CreateJob(job);
  failed.state = JobState::kFailed;
  failed.error = "why";
  ASSERT_TRUE(Db().UpdateJob(failed).ok());
  JobRecord running = first;
  running.state = JobState::kRunning;
  ASSERT_TRUE(Db().UpdateJob(running).ok());
  const absl::StatusOr<std::map<JobState, int64_t>> counts = Db().CountJobs();
  ASSERT_TRUE(counts.ok()) << counts.status();
  EXPECT_EQ(*counts, (std::map<JobState, int64_t>{
                         {JobState::kQueued, 1}, {JobState::kRunning, 1}, {JobState::kFailed, 1}}));
}

TEST_F(StorageTest, OpenInterruptsTheJobsADeadProcessLeftUnfinished) {
  const JobRecord queued = *Db().CreateJob({});
  JobRecord running = *Db().CreateJob({});
  running.state = JobState::kRunning;
  ASSERT_TRUE(Db().UpdateJob(running).ok());
  JobRecord failed = *Db().CreateJob({});
  failed.state = JobState::kFailed;
  failed.error = "boom";
  failed.finished_unix_ms = 1234;
  ASSERT_TRUE(Db().UpdateJob(failed).ok());
  Close();

  for (const std::string& id : {queued.job_id, running.job_id}) {
    const absl::StatusOr<JobRecord> job = Db().GetJob(id);
    ASSERT_TRUE(job.ok()) << job.status();
    EXPECT_EQ(job->state, JobState::kInterrupted) << id;
    EXPECT_GT(job->finished_unix_ms, 0) << id;
    EXPECT_THAT(job->error, HasSubstr("stopped before the job ended"));
  }
  const JobRecord kept = *Db().GetJob(failed.job_id);
  EXPECT_EQ(kept.state, JobState::kFailed);
  EXPECT_EQ(kept.error, "boom");
  EXPECT_EQ(kept.finished_unix_ms, 1234);
}

TEST_F(StorageSpaceTest, FinishPropagationReplacesItsDescriptorsOutputInOneTransaction) {
  const auto [walk, wave, space_id, manual] = InsertLabelledLibrary();
  EXPECT_EQ(*Db().ManualDescriptors(), (std::vector<std::string>{"kick", "wave"}));

  // The output of one job for `descriptors`: `count` kick labels on the wave clip.
  const auto output = [&](const std::vector<std::string>& descriptors, int count) {
    PropagationOutput out;
    out.job = *Db().CreateJob({});
    out.job.state = JobState::kSucceeded;
    out.space_id = space_id;
    out.descriptors = descriptors;
    for (int i = 0; i < count; ++i) {
      LabelRecord label = Manual(wave, 10 * i, 10 * i + 5, "kick", 0.5);
      label.origin = LabelOrigin::kPropagated;
      label.source_label_id = manual[0];
      label.space_id = space_id;
      label.score = 0.1;
      label.job_id = out.job.job_id;
      out.labels.push_back(label);
    }
    return out;
  };
  const PropagationOutput first = output({"kick"}, 3);
  EXPECT_EQ(*Db().FinishPropagation(first), 3);
  EXPECT_EQ(Db().GetJob(first.job.job_id)->labels_written, 3);
  EXPECT_EQ(Db().GetJob(first.job.job_id)->state, JobState::kSucceeded);

  // A stopped write and a bad label change nothing: neither the labels nor the job.
  PropagationOutput second = output({"kick"}, 2);
  EXPECT_EQ(Db().FinishPropagation(second, {.should_stop = [] { return true; }}).status().code(),
            absl::StatusCode::kCancelled);
  EXPECT_EQ(Db().GetJob(second.job.job_id)->state, JobState::kQueued);
  PropagationOutput bad = second;
  bad.labels[1].descriptor = "wave";
  const absl::Status refused = Db().FinishPropagation(bad).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(refused.message()), HasSubstr("labels[1].descriptor"));
  EXPECT_EQ(Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels.size(), 3u);

  // The re-run replaces the first run's kick labels; manual labels stay; a label whose source
  // was deleted meanwhile is left out.
  EXPECT_EQ(*Db().FinishPropagation(second), 2);
  std::vector<LabelRecord> propagated =
      Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels;
  ASSERT_EQ(propagated.size(), 2u);
  for (const LabelRecord& label : propagated) EXPECT_EQ(label.job_id, second.job.job_id);
  EXPECT_EQ(Db().ListLabels({}, {.origin = LabelOrigin::kManual})->labels.size(), 2u);
  PropagationOutput orphan = output({"kick"}, 2);
  orphan.labels[0].source_label_id = manual[1];
  ASSERT_TRUE(Db().DeleteLabels(std::vector<int64_t>{manual[1]}).ok());
  EXPECT_EQ(*Db().FinishPropagation(orphan), 1);
  EXPECT_EQ(Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels.size(), 1u);

  // A space deleted while the job ran: refused (not a foreign-key error), the job row unchanged.
  PropagationOutput gone = output({"kick"}, 1);
  ASSERT_TRUE(Db().DeleteSpace("body").ok());
  const absl::Status no_space = Db().FinishPropagation(gone).status();
  EXPECT_EQ(no_space.code(), absl::StatusCode::kNotFound) << no_space;
  EXPECT_THAT(std::string(no_space.message()), HasSubstr("deleted while the job ran"));
  EXPECT_EQ(Db().GetJob(gone.job.job_id)->state, JobState::kQueued);
}

}  // namespace
}  // namespace motiondb::storage
