// The SQLite storage's labels on real files (storage_fixture.h): listed, found, timelined and
// paged; queries and batches refused whole; deletes that cascade.
#include "storage/database.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/clip_builder.h"
#include "tests/storage_fixture.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb::storage {
namespace {

using ::testing::HasSubstr;

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

}  // namespace
}  // namespace motiondb::storage
