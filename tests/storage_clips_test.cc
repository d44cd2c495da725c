// The SQLite storage's clips on real files (storage_fixture.h): round trips and frame ranges,
// listing, pagination, skeleton sharing, clip names and content hashes, replacing and updating
// clips.
#include "storage/database.h"

#include <map>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "storage/content_hash.h"
#include "tests/clip_builder.h"
#include "tests/storage_fixture.h"
#include "tests/synthetic_motion.h"

namespace motiondb::storage {
namespace {

using ::testing::HasSubstr;

// `skeleton` with its last joint renamed: another topology.
std::shared_ptr<const Skeleton> Renamed(const Skeleton& skeleton, const std::string& name) {
  std::vector<Joint> joints = skeleton.joints();
  joints.back().name = name;
  return std::make_shared<const Skeleton>(*Skeleton::Create(std::move(joints)));
}

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

// An FBX or glTF file's facts are kept for its clip, listed with it, and go with it.
TEST_F(StorageTest, AClipKeepsWhatItsFileSaidOfItself) {
  ClipRecord record = Named("take");
  record.source_facts = {"fbx", 0.01, "Z"};
  const int64_t id = Insert(record, Motion(testing::ChainSkeleton(), 5));
  const int64_t plain = Insert(Named("plain"), Motion(testing::ChainSkeleton(), 5));
  const absl::StatusOr<ClipRecord> stored = Db().GetClipRecord(id);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(stored->source_facts.format, "fbx");
  EXPECT_DOUBLE_EQ(stored->source_facts.unit_m, 0.01);
  EXPECT_EQ(stored->source_facts.up_axis, "Z");
  const absl::StatusOr<ClipRecord> bvh = Db().GetClipRecord(plain);
  ASSERT_TRUE(bvh.ok()) << bvh.status();
  EXPECT_EQ(bvh->source_facts.format, "");
  EXPECT_EQ(bvh->source_facts.unit_m, 0);
  ASSERT_TRUE(Db().DeleteClip(id).ok());
  EXPECT_EQ(*Raw()->QueryInt64("SELECT count(*) FROM clip_sources"), 0);
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

// A cluster's shard stores clips under the ids its router hands out.
TEST_F(StorageTest, AClipMayBeGivenItsId) {
  const Clip clip = Motion(testing::ChainSkeleton(), 4);
  const InsertClipOptions given{.replace_clip_id = 0, .clip_id = 5001};
  const absl::StatusOr<int64_t> stored = Db().InsertClip(Named("routed"), clip, {}, given);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(*stored, 5001);
  EXPECT_EQ(Db().GetClipRecordByName("routed")->clip_id, 5001);
  ExpectSameFrames(clip, Db().GetClip(5001)->clip);

  // An id held, or not positive, is refused and stores nothing.
  const Counts before = CountsNow();
  const absl::StatusOr<int64_t> taken = Db().InsertClip(Named("other"), clip, {}, given);
  EXPECT_EQ(taken.status().code(), absl::StatusCode::kAlreadyExists);
  EXPECT_THAT(taken.status().message(), HasSubstr("5001"));
  const absl::StatusOr<int64_t> negative =
      Db().InsertClip(Named("other"), clip, {}, {.replace_clip_id = 0, .clip_id = -3});
  EXPECT_EQ(negative.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  EXPECT_EQ(Db().GetClipRecordByName("other").status().code(), absl::StatusCode::kNotFound);

  // An id below the highest is free to be given; the database's own come after the highest.
  EXPECT_EQ(*Db().InsertClip(Named("lower"), clip, {}, {.replace_clip_id = 0, .clip_id = 7}), 7);
  EXPECT_EQ(Insert(Named("next"), clip), 5002);
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
  EXPECT_EQ(Db().InsertClip(Named("take_001"), run, {{999, projection}},
                            {.replace_clip_id = walk, .clip_id = 0})
                .status()
                .code(),
            absl::StatusCode::kNotFound);
  // So does one whose name belongs to a clip other than the replaced one.
  EXPECT_EQ(Db().InsertClip(Named("take_002"), run, {{space_id, ProjectionOf(0, run)}},
                            {.replace_clip_id = walk, .clip_id = 0})
                .status()
                .code(),
            absl::StatusCode::kAlreadyExists);
  const absl::StatusOr<int64_t> unknown =
      Db().InsertClip(Named("take_009"), run, {{space_id, ProjectionOf(0, run)}},
                      {.replace_clip_id = 4242, .clip_id = 0});
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(unknown.status().message(), HasSubstr("4242"));
  EXPECT_EQ(AsTuple(CountsNow()), AsTuple(before));
  EXPECT_EQ(Db().GetClipRecord(walk)->content_hash, old_hash);

  const Projection run_projection = ProjectionOf(0, run);
  const absl::StatusOr<int64_t> replaced =
      Db().InsertClip(Named("take_001", {"new"}), run, {{space_id, run_projection}},
                      {.replace_clip_id = walk, .clip_id = 0});
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

}  // namespace
}  // namespace motiondb::storage
