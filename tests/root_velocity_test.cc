// The pelvis's velocity in the facing's frame (core/space/root_velocity.h), on hand-made BVH
// clips whose numbers can be worked out by hand.
#include "core/space/root_velocity.h"

#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/bvh/bvh_reader.h"
#include "core/space/heading.h"
#include "core/space/pose_encoder.h"

namespace motiondb {
namespace {

constexpr double kFps = 25.0;  // a frame time that prints exactly (0.04)

// A still Root above Hips (as in Bandai's files) with two legs of 45 + 40 + 5 units and a spine
// of 30 + 20. Every length is times `scale`.
std::string Hierarchy(double scale) {
  const auto offset = [&](double y) { return absl::StrCat("OFFSET 0 ", y * scale, " 0\n"); };
  const std::string rotations = "CHANNELS 3 Zrotation Xrotation Yrotation\n";
  const auto leg = [&](const std::string& side) {
    return absl::StrCat("JOINT Leg", side, "\n{\n", offset(-45), rotations, "JOINT Foot", side,
                        "\n{\n", offset(-40), rotations, "End Site\n{\n", offset(-5), "}\n}\n}\n");
  };
  return absl::StrCat(
      "HIERARCHY\nROOT Root\n{\n", offset(0),
      "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\nJOINT Hips\n{\n",
      offset(90), "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n",
      leg("L"), leg("R"), "JOINT Spine\n{\n", offset(30), rotations, "End Site\n{\n", offset(20),
      "}\n}\n}\n}\n");
}

// 31 frames at 25 fps of Hips facing `yaw_degrees` about Y and moving at `velocity` (units a
// second, world X and Z) on the ground.
Clip MovingClip(double yaw_degrees, Eigen::Vector2d velocity, double scale = 1.0) {
  std::string text =
      absl::StrCat(Hierarchy(scale), "MOTION\nFrames: 31\nFrame Time: ", 1.0 / kFps, "\n");
  for (int f = 0; f < 31; ++f) {
    const Eigen::Vector2d at = velocity * (f / kFps);
    // 17 significant digits: StrCat's 6 would make the path's speed wobble.
    absl::StrAppend(&text,
                    absl::StrFormat("0 0 0 0 0 0 %.17g %.17g %.17g 0 0 %.17g", at.x(), 90 * scale,
                                    at.y(), yaw_degrees),
                    " 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n");
  }
  absl::StatusOr<BvhReadResult> read = ReadBvh(text);
  EXPECT_TRUE(read.ok()) << read.status();
  return std::move(read->clip);
}

RowMatrixXd VelocityOf(const Clip& clip) {
  RowMatrixXd rotations = clip.rotations();
  const Eigen::VectorXd yaw = RemoveHeading(clip.skeleton(), &rotations);
  return RootVelocity(clip, yaw, 5);
}

// Every frame's velocity is `expected` (ends included: a steady motion has no edge effects).
void ExpectSteady(const RowMatrixXd& velocity, Eigen::RowVector2d expected) {
  ASSERT_EQ(velocity.rows(), 31);
  ASSERT_EQ(velocity.cols(), kRootVelocityDims);
  for (Eigen::Index f = 0; f < velocity.rows(); ++f) {
    EXPECT_LT((velocity.row(f) - expected).norm(), 1e-9)
        << "frame " << f << ": " << velocity.row(f);
  }
}

TEST(RootVelocityTest, LegLengthIsTheMedianReachBelowThePelvis) {
  EXPECT_DOUBLE_EQ(LegLength(MovingClip(0, {0, 0}).skeleton()), 90.0);
  EXPECT_DOUBLE_EQ(LegLength(MovingClip(0, {0, 0}, 2.5).skeleton()), 225.0);
  // One chain below the pelvis: its length, whatever its direction; a lone joint: 1.
  absl::StatusOr<BvhReadResult> upright = ReadBvh(
      "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
      "JOINT Spine\n{\nOFFSET 0 30 40\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
      "End Site\n{\nOFFSET 0 0 0\n}\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0\n");
  ASSERT_TRUE(upright.ok()) << upright.status();
  EXPECT_DOUBLE_EQ(LegLength(upright->clip.skeleton()), 50.0);
  absl::StatusOr<BvhReadResult> lone = ReadBvh(
      "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
      "}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n");
  ASSERT_TRUE(lone.ok()) << lone.status();
  EXPECT_DOUBLE_EQ(LegLength(lone->clip.skeleton()), 1.0);
}

TEST(RootVelocityTest, ForwardSidewaysAndBackwardsInLegLengthsASecond) {
  // Facing along +Z (yaw 0), 90 units a second is one leg length a second.
  ExpectSteady(VelocityOf(MovingClip(0, {0, 90})), {0, 1});
  ExpectSteady(VelocityOf(MovingClip(0, {0, -45})), {0, -0.5});
  ExpectSteady(VelocityOf(MovingClip(0, {180, 0})), {2, 0});
  ExpectSteady(VelocityOf(MovingClip(0, {0, 0})), {0, 0});
}

TEST(RootVelocityTest, TheSameWalkInAnyDirectionAndAtAnySize) {
  const double turn = 70.0 * std::numbers::pi / 180.0;
  // R_y(turn) takes the facing's +Z to (sin, cos) and its +X to (cos, -sin) in world X, Z.
  const Eigen::Vector2d forward(std::sin(turn), std::cos(turn));
  const Eigen::Vector2d sideways(std::cos(turn), -std::sin(turn));
  ExpectSteady(VelocityOf(MovingClip(70, 90 * forward)), {0, 1});
  ExpectSteady(VelocityOf(MovingClip(70, 45 * sideways)), {0.5, 0});
  // Turned round and walking the other way: the same walk.
  ExpectSteady(VelocityOf(MovingClip(-110, -90 * forward)), {0, 1});
  ExpectSteady(VelocityOf(MovingClip(70, 3 * 90 * forward, 3.0)), {0, 1});
}

TEST(RootVelocityTest, PoseVectorsEndWithItUnlessTurnedOffOrTheFacingIsKept) {
  EXPECT_EQ(PoseDims(22, {}), 3 * 22 + 1 + kRootVelocityDims);
  EXPECT_EQ(PoseDims(22, {.root_velocity = false}), 3 * 22 + 1);
  EXPECT_EQ(PoseDims(22, {.remove_heading = false}), 3 * 22);
  const Clip clip = MovingClip(30, {45, 0});
  const PoseRotations pose = ComputePoseRotations(clip, {});
  ASSERT_EQ(pose.root_velocity.rows(), 31);
  EXPECT_EQ(pose.root_velocity, VelocityOf(clip));
  EXPECT_EQ(ComputePoseRotations(clip, {.root_velocity = false}).root_velocity.size(), 0);
  EXPECT_EQ(ComputePoseRotations(clip, {.remove_heading = false}).root_velocity.size(), 0);
  const int joints = clip.skeleton().joint_count();
  const RowMatrixXd references =
      RowMatrixXd::Zero(joints, 4).rowwise() + Eigen::RowVector4d(1, 0, 0, 0);
  const RowMatrixXd poses = EncodePoses(pose, references);
  ASSERT_EQ(poses.cols(), PoseDims(joints, {}));
  EXPECT_EQ(poses.col(3 * joints), pose.yaw_rate);
  EXPECT_EQ(poses.rightCols<kRootVelocityDims>(), pose.root_velocity);
  // The extra columns do not shape the body.
  EXPECT_EQ(DecodePoses(poses, references), DecodePoses(poses.leftCols(3 * joints), references));
}

}  // namespace
}  // namespace motiondb
