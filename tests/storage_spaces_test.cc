// The SQLite storage's spaces and projections on real files (storage_fixture.h): round trips,
// a projection for every clip, cascades, writes refused, stopped or failed midway that change
// nothing, and a reopened file that keeps everything.
#include "storage/database.h"

#include <cmath>
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/space/space_serialization.h"
#include "storage/schema.h"
#include "storage/sqlite_connection.h"
#include "tests/clip_builder.h"
#include "tests/storage_fixture.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb::storage {
namespace {

using ::testing::HasSubstr;

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
      Db().InsertClip(Named("walk"), walk_, walk_projection,
                      {.replace_clip_id = walk, .clip_id = 0}, stop)
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

// A map change re-projects a skeleton's clips into its spaces over several skeletons in the
// overrides' transaction: all of its clips or none, into spaces that list it, of the space's
// width; on any error neither the overrides nor a projection change.
TEST_F(StorageSpaceTest, OverridesAndTheirReprojectionsAreOneTransaction) {
  const int64_t walk = Insert(Named("walk"), walk_);
  const int64_t wave = Insert(Named("wave"), wave_);
  const int64_t skeleton = Db().GetClipRecord(walk)->skeleton_id;
  SpaceOptions options;
  options.representation = SpaceRepresentation::kCanonicalBones;
  const absl::StatusOr<MotionSpace> bones =
      MotionSpace::Build({{"walk.bvh", walk_, std::nullopt}}, options);
  ASSERT_TRUE(bones.ok()) << bones.status();
  const auto projection = [&](int64_t clip_id, const Clip& clip, double shift) {
    Projection p{clip_id, bones->ProjectClip(clip, 8)->cast<float>()};
    p.coordinates.array() += static_cast<float>(shift);
    return p;
  };
  SpaceRecord record = SpaceNamed("bones", skeleton);
  record.skeleton_ids = {skeleton};
  const absl::StatusOr<int64_t> space =
      Db().InsertSpace(record, *bones, {projection(walk, walk_, 0), projection(wave, wave_, 0)});
  ASSERT_TRUE(space.ok()) << space.status();
  const int64_t joints = *Db().InsertSpace(SpaceNamed("body", skeleton), space_,
                                           {ProjectionOf(walk, walk_), ProjectionOf(wave, wave_)});
  const SlotOverrideChange change{.set = {{HumanoidSlot::kHead, "Neck"}}};
  const auto stored = [&] { return Db().LoadProjections(*space)->front().coordinates; };
  const RowMatrixXf before = stored();

  for (const auto& [reprojection, code, message] :
       std::vector<std::tuple<SpaceReprojection, absl::StatusCode, std::string>>{
           {{*space, {projection(walk, walk_, 1)}},
            absl::StatusCode::kFailedPrecondition,
            absl::StrCat("no new projection into space ", *space, " of clip ", wave)},
           {{*space,
             {projection(walk, walk_, 1), projection(wave, wave_, 1), projection(walk, walk_, 1)}},
            absl::StatusCode::kInvalidArgument,
            "which is not one of skeleton"},
           {{*space, {projection(walk, walk_, 1), {wave, RowMatrixXf::Zero(3, 40)}}},
            absl::StatusCode::kInvalidArgument,
            "projection of clip"},
           {{joints, {projection(walk, walk_, 1), projection(wave, wave_, 1)}},
            absl::StatusCode::kFailedPrecondition,
            "is no space over several skeletons that lists skeleton"}}) {
    const absl::StatusOr<SkeletonRecord> refused =
        Db().UpdateSlotOverrides(skeleton, change, {reprojection});
    EXPECT_EQ(refused.status().code(), code) << message;
    EXPECT_THAT(std::string(refused.status().message()), ::testing::HasSubstr(message));
    EXPECT_TRUE(Db().GetSkeleton(skeleton)->slot_overrides.empty()) << message;
    EXPECT_EQ(stored(), before) << message;
  }

  const absl::StatusOr<SkeletonRecord> changed = Db().UpdateSlotOverrides(
      skeleton, change, {{*space, {projection(walk, walk_, 1), projection(wave, wave_, 1)}}});
  ASSERT_TRUE(changed.ok()) << changed.status();
  EXPECT_EQ(changed->slot_overrides.size(), 1u);
  EXPECT_EQ(stored(), (before.array() + 1.0f).matrix());
  EXPECT_EQ(Db().LoadProjections(*space)->size(), 2u);
}

}  // namespace
}  // namespace motiondb::storage
