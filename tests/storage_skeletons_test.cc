// Skeletons as stored: their joints and their humanoid slot overrides.
#include "tests/storage_fixture.h"

namespace motiondb::storage {
namespace {

using Slot = HumanoidSlot;

std::vector<std::pair<Slot, std::string>> AsPairs(const std::vector<SlotOverride>& overrides) {
  std::vector<std::pair<Slot, std::string>> pairs;
  for (const SlotOverride& o : overrides) pairs.emplace_back(o.slot, o.joint);
  return pairs;
}

TEST_F(StorageTest, GetSkeletonGivesTheFirstClipsJoints) {
  const int64_t clip = Insert(Named("h"), Motion(testing::HumanoidSkeleton(true), 2));
  const int64_t skeleton_id = Db().GetClipRecord(clip)->skeleton_id;
  const absl::StatusOr<SkeletonRecord> record = Db().GetSkeleton(skeleton_id);
  ASSERT_TRUE(record.ok()) << record.status();
  EXPECT_EQ(record->summary.clip_count, 1);
  EXPECT_EQ(record->summary.first_clip_name, "h");
  ExpectSameLayout(*record->skeleton, *testing::HumanoidSkeleton(true));
  EXPECT_TRUE(record->slot_overrides.empty());
  EXPECT_EQ(Db().GetSkeleton(skeleton_id + 1).status().code(), absl::StatusCode::kNotFound);
}

TEST_F(StorageTest, ASkeletonWithoutClipsKeepsItsNamesAndParents) {
  const int64_t clip = Insert(Named("h"), Motion(testing::HumanoidSkeleton(true), 2));
  const int64_t skeleton_id = Db().GetClipRecord(clip)->skeleton_id;
  ASSERT_TRUE(Db().DeleteClip(clip).ok());
  const absl::StatusOr<SkeletonRecord> record = Db().GetSkeleton(skeleton_id);
  ASSERT_TRUE(record.ok()) << record.status();
  EXPECT_TRUE(record->skeleton->SameTopology(*testing::HumanoidSkeleton(true)));
}

TEST_F(StorageTest, SlotOverridesPersistAcrossReopen) {
  const int64_t clip = Insert(Named("h"), Motion(testing::HumanoidSkeleton(true), 2));
  const int64_t skeleton_id = Db().GetClipRecord(clip)->skeleton_id;
  const absl::StatusOr<SkeletonRecord> set = Db().UpdateSlotOverrides(
      skeleton_id, {.set = {{Slot::kLeftHand, "Hand_R"}, {Slot::kRightHand, "Hand_L"}}});
  ASSERT_TRUE(set.ok()) << set.status();
  const std::vector<std::pair<Slot, std::string>> expected = {{Slot::kLeftHand, "Hand_R"},
                                                              {Slot::kRightHand, "Hand_L"}};
  EXPECT_EQ(AsPairs(set->slot_overrides), expected);
  Close();
  EXPECT_EQ(AsPairs(Db().GetSkeleton(skeleton_id)->slot_overrides), expected);

  // Clearing one keeps the other; clearing a slot without an override is no error.
  const absl::StatusOr<SkeletonRecord> cleared =
      Db().UpdateSlotOverrides(skeleton_id, {.clear = {Slot::kLeftHand, Slot::kHead}});
  ASSERT_TRUE(cleared.ok()) << cleared.status();
  const std::vector<std::pair<Slot, std::string>> right_only = {{Slot::kRightHand, "Hand_L"}};
  EXPECT_EQ(AsPairs(cleared->slot_overrides), right_only);
  Close();
  EXPECT_EQ(AsPairs(Db().GetSkeleton(skeleton_id)->slot_overrides), right_only);
}

TEST_F(StorageTest, BadSlotOverridesChangeNothing) {
  const int64_t clip = Insert(Named("h"), Motion(testing::HumanoidSkeleton(true), 2));
  const int64_t skeleton_id = Db().GetClipRecord(clip)->skeleton_id;
  ASSERT_TRUE(Db().UpdateSlotOverrides(skeleton_id, {.set = {{Slot::kHead, "Neck"}}}).ok());
  const std::vector<std::pair<Slot, std::string>> before = {{Slot::kHead, "Neck"}};
  const auto refused = [&](const SlotOverrideChange& change, absl::StatusCode code,
                           const std::string& message) {
    const absl::StatusOr<SkeletonRecord> result = Db().UpdateSlotOverrides(skeleton_id, change);
    EXPECT_EQ(result.status().code(), code) << result.status();
    EXPECT_EQ(result.status().message(), message);
    EXPECT_EQ(AsPairs(Db().GetSkeleton(skeleton_id)->slot_overrides), before);
  };
  // The first set is good: the batch is refused whole.
  refused({.set = {{Slot::kLeftFoot, "Foot_L"}, {Slot::kLeftHand, "hand_l"}}},
          absl::StatusCode::kInvalidArgument,
          absl::StrCat("set[1].joint: skeleton ", skeleton_id, " has no joint named 'hand_l'"));
  refused({.set = {{Slot::kLeftHand, "Hand_L"}, {Slot::kLeftHand, "Hand_R"}}},
          absl::StatusCode::kInvalidArgument, "set[1].slot: LeftHand is set twice");
  refused({.set = {{Slot::kLeftHand, "Hand_L"}}, .clear = {Slot::kLeftHand}},
          absl::StatusCode::kInvalidArgument, "set[0].slot: LeftHand is both set and cleared");
  refused({.set = {{Slot::kNeck, "Neck"}}}, absl::StatusCode::kInvalidArgument,
          "set[0].joint: 'Neck' is already the override of slot Head; clear that slot or set it "
          "to another joint");
  const absl::StatusOr<SkeletonRecord> stopped =
      Db().UpdateSlotOverrides(skeleton_id, {.set = {{Slot::kLeftHand, "Hand_L"}}}, {},
                               {.should_stop = [] { return true; }});
  EXPECT_EQ(stopped.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(AsPairs(Db().GetSkeleton(skeleton_id)->slot_overrides), before);
  EXPECT_EQ(Db().UpdateSlotOverrides(skeleton_id + 1, {.clear = {Slot::kHead}}).status().code(),
            absl::StatusCode::kNotFound);
}

TEST_F(StorageTest, ASchemaSixFileGainsTheOverridesTable) {
  const int64_t clip = Insert(Named("h"), Motion(testing::HumanoidSkeleton(true), 2));
  const int64_t skeleton_id = Db().GetClipRecord(clip)->skeleton_id;
  Close();
  // The file as version 6 left it.
  ASSERT_TRUE(Raw()
                  ->Execute("DROP TABLE skeleton_slot_overrides; DROP TABLE clip_sources; "
                            "DROP TABLE space_skeletons; "
                            "PRAGMA user_version = 6")
                  .ok());
  const absl::StatusOr<SkeletonRecord> record = Db().GetSkeleton(skeleton_id);
  ASSERT_TRUE(record.ok()) << record.status();
  EXPECT_TRUE(record->slot_overrides.empty());
  EXPECT_EQ(*Raw()->QueryInt64("PRAGMA user_version"), LatestSchemaVersion());
  EXPECT_TRUE(Db().UpdateSlotOverrides(skeleton_id, {.set = {{Slot::kHead, "Neck"}}}).ok());
}

}  // namespace
}  // namespace motiondb::storage
