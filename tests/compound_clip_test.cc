#include "testing/compound_clip.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "core/motion/forward_kinematics.h"
#include "core/space/heading.h"
#include "testing/synthetic_corpus.h"
#include "tests/clip_builder.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using testing::GenerateSyntheticCorpus;
using ::testing::HasSubstr;
using testing::SyntheticAction;
using testing::SyntheticCorpusOptions;

// One instance of `action` at `fps`, with half a second of rest either side.
Clip OneAction(SyntheticAction action, uint64_t seed, double fps = 30) {
  SyntheticCorpusOptions options;
  options.seed = seed;
  options.fps = fps;
  options.script = {{action, 1}};
  options.rest_min_s = options.rest_max_s = 0.5;
  options.threads = 1;
  return GenerateSyntheticCorpus(options)->clips[0];
}

// `clip` walked 3 m along X (its root's positions shifted), so that B starts elsewhere than A ends.
Clip Moved(const Clip& clip) {
  RowMatrixXd positions = clip.positions();
  positions.col(3 * clip.skeleton().position_slot(0)).array() += 300;
  positions.col(3 * clip.skeleton().position_slot(0) + 2).array() -= 50;
  return *Clip::Create(clip.shared_skeleton(), clip.frame_time(), clip.rotations(), positions);
}

Eigen::Vector3d Pelvis(const Clip& clip, int frame) {
  const int pelvis = FindPelvis(clip.skeleton());
  return ForwardKinematics(clip).block<1, 3>(frame, 3 * pelvis).transpose();
}

TEST(ConcatenateWithHold, HoldsTheLastPoseThenPlaysTheSecondClipOnFromWhereTheFirstEnded) {
  const Clip a = OneAction(SyntheticAction::kRightArmRaise, 1);
  const Clip b = Moved(OneAction(SyntheticAction::kLeftArmRaise, 2));
  const testing::CompoundClip compound = *testing::ConcatenateWithHold(a, b, {2.0, 0.25});
  const Clip& clip = compound.clip;
  const int hold = 60, blend = 8;  // 2 s and 0.25 s at 30 Hz, rounded
  ASSERT_EQ(clip.frame_count(), a.frame_count() + hold + blend + b.frame_count());
  EXPECT_EQ(compound.first.first, 0);
  EXPECT_EQ(compound.first.last, a.frame_count() - 1);
  EXPECT_EQ(compound.second.first, a.frame_count() + hold + blend);
  EXPECT_EQ(compound.second.last, clip.frame_count() - 1);
  EXPECT_EQ(clip.frame_time(), a.frame_time());

  EXPECT_EQ(clip.rotations().topRows(a.frame_count()), a.rotations());
  EXPECT_EQ(clip.positions().topRows(a.frame_count()), a.positions());
  for (int f = a.frame_count(); f < a.frame_count() + hold; ++f) {
    EXPECT_EQ(clip.rotations().row(f), a.rotations().row(a.frame_count() - 1)) << f;
    EXPECT_EQ(clip.positions().row(f), a.positions().row(a.frame_count() - 1)) << f;
  }
  // The second clip's poses are its own; its root moved on the ground only, by one offset.
  EXPECT_EQ(clip.rotations().bottomRows(b.frame_count()), b.rotations());
  const int slot = b.skeleton().position_slot(0);
  const RowMatrixXd moved = clip.positions().bottomRows(b.frame_count()).middleCols<3>(3 * slot) -
                            b.positions().middleCols<3>(3 * slot);
  for (int f = 0; f < b.frame_count(); ++f) {
    EXPECT_NEAR((moved.row(f) - moved.row(0)).norm(), 0, 1e-9);
  }
  EXPECT_NEAR(moved(0, 1), 0, 1e-9);      // the vertical is kept
  EXPECT_GT(std::abs(moved(0, 0)), 250);  // B was 3 m away
  // The pelvis carries on where it stopped: the first's last position, horizontally.
  const Eigen::Vector3d end = Pelvis(a, a.frame_count() - 1);
  const Eigen::Vector3d start = Pelvis(clip, compound.second.first);
  EXPECT_NEAR(start.x(), end.x(), 1e-6);
  EXPECT_NEAR(start.z(), end.z(), 1e-6);
  // The transition moves the root in a straight line, in even steps.
  const int from = a.frame_count() - 1;
  const Eigen::Vector3d step = clip.root_position(from + hold + 1) - clip.root_position(from);
  for (int f = from + hold + 1; f <= compound.second.first; ++f) {
    EXPECT_NEAR((clip.root_position(f) - clip.root_position(f - 1) - step).norm(), 0, 1e-9) << f;
  }
}

// Bandai's layout: a still joint_Root above Hips, position channels on every joint. The pelvis
// (Hips) carries on from where it stopped although the shift goes to joint_Root.
TEST(ConcatenateWithHold, CarriesThePelvisOnInBandaiTakes) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  const std::filesystem::path folder = mocap / "bandai2-normal";
  const Clip a =
      ReadBvhFile((folder / "dataset-2_raise-up-right-hand_normal_001.bvh").string())->clip;
  const Clip b = ReadBvhFile((folder / "dataset-2_wave-left-hand_normal_001.bvh").string())->clip;
  ASSERT_EQ(a.skeleton().joint(FindPelvis(a.skeleton())).name, "Hips");
  const testing::CompoundClip compound = *testing::ConcatenateWithHold(a, b, {1.0, 0.25});
  const Eigen::Vector3d end = Pelvis(a, a.frame_count() - 1);
  const Eigen::Vector3d start = Pelvis(compound.clip, compound.second.first);
  EXPECT_NEAR(start.x(), end.x(), 1e-6);
  EXPECT_NEAR(start.z(), end.z(), 1e-6);
  EXPECT_NEAR(start.y(), Pelvis(b, 0).y(), 1e-6);  // the vertical is the second take's own
  EXPECT_EQ(compound.clip.rotations().bottomRows(b.frame_count()), b.rotations());
}

TEST(ConcatenateWithHold, ResamplesTheSecondClipToTheFirstsRate) {
  const Clip a = OneAction(SyntheticAction::kRightArmRaise, 1, 30);
  const Clip b = OneAction(SyntheticAction::kShrug, 2, 60);
  const testing::CompoundClip compound = *testing::ConcatenateWithHold(a, b, {0.3, 0.0});
  EXPECT_EQ(compound.clip.frame_time(), a.frame_time());
  EXPECT_EQ(compound.second.first, a.frame_count() + 9);
  EXPECT_NEAR(compound.second.size(), b.frame_count() / 2, 1);
}

TEST(ConcatenateWithHold, RefusesOtherSkeletonsAndBadOptions) {
  const Clip a = OneAction(SyntheticAction::kRightArmRaise, 1);
  const Clip chain = testing::MakeClip(
      testing::ChainSkeleton(), 10, a.frame_time(), [](int, int) { return Quat::Identity(); },
      [](int, int) { return Eigen::Vector3d::Zero(); });
  EXPECT_THAT(testing::ConcatenateWithHold(a, chain, {}).status().message(),
              HasSubstr("21 and 3 joints"));

  std::vector<Joint> joints = a.skeleton().joints();
  joints[3].channels = {Channel::kXrotation, Channel::kYrotation, Channel::kZrotation};
  const auto reordered = std::make_shared<const Skeleton>(*Skeleton::Create(joints));
  const Clip other = *Clip::Create(reordered, a.frame_time(), a.rotations(), a.positions());
  const absl::Status channels = testing::ConcatenateWithHold(a, other, {}).status();
  EXPECT_EQ(channels.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(channels.message(), HasSubstr("joint 3"));

  joints = a.skeleton().joints();
  joints[0].channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
  const auto fixed = std::make_shared<const Skeleton>(*Skeleton::Create(joints));
  const Clip rooted =
      *Clip::Create(fixed, a.frame_time(), a.rotations(), RowMatrixXd(a.frame_count(), 0));
  EXPECT_THAT(testing::ConcatenateWithHold(rooted, rooted, {}).status().message(),
              HasSubstr("no position channels"));

  for (const testing::CompoundOptions options :
       {testing::CompoundOptions{-1, 0.25}, testing::CompoundOptions{1, NAN}}) {
    const absl::Status status = testing::ConcatenateWithHold(a, a, options).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  }
}

}  // namespace
}  // namespace motiondb
