#include "core/motion/forward_kinematics.h"

#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"

namespace motiondb {
namespace {

// Hand-worked cases read from BVH text, so that channels, rotation orders and offsets come
// the way a file gives them. Rotations are right-handed: Rz(90) takes +x to +y, Ry(90) takes
// +x to -z, Rx(90) takes +y to +z.

// A root at `root_channels` (its values first on the row) with one child 10 along x, whose
// own child (a leaf) is 10 further along x; the middle joint rotates in `order` ("XYZ" lists
// Xrotation Yrotation Zrotation).
std::string Chain(const std::string& order, const std::string& row) {
  std::string channels;
  for (char axis : order) absl::StrAppend(&channels, " ", std::string(1, axis), "rotation");
  return absl::StrCat(
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n"
      " CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      " JOINT Upper\n {\n  OFFSET 10 0 0\n  CHANNELS 3",
      channels,
      "\n  JOINT Lower\n  {\n   OFFSET 10 0 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "   End Site\n   {\n    OFFSET 1 0 0\n   }\n  }\n }\n}\n"
      "MOTION\nFrames: 1\nFrame Time: 0.04\n",
      row, "\n");
}

RowMatrixXd WorldOf(const std::string& bvh) {
  absl::StatusOr<BvhReadResult> read = ReadBvh(bvh);
  EXPECT_TRUE(read.ok()) << read.status();
  return read.ok() ? ForwardKinematics(read->clip) : RowMatrixXd();
}

void ExpectJoint(const RowMatrixXd& world, int frame, int joint, const Eigen::Vector3d& expected) {
  ASSERT_GT(world.rows(), frame);
  const Eigen::Vector3d got = world.block<1, 3>(frame, 3 * joint).transpose();
  EXPECT_LT((got - expected).norm(), 1e-9) << "joint " << joint << " at (" << got.transpose()
                                           << "), expected (" << expected.transpose() << ")";
}

TEST(ForwardKinematics, RestPoseAddsOffsetsToTheRootTranslation) {
  const RowMatrixXd world = WorldOf(Chain("XYZ", "1 2 3 0 0 0 0 0 0 0 0 0"));
  ASSERT_EQ(world.rows(), 1);
  ASSERT_EQ(world.cols(), 9);
  ExpectJoint(world, 0, 0, {1, 2, 3});
  ExpectJoint(world, 0, 1, {11, 2, 3});
  ExpectJoint(world, 0, 2, {21, 2, 3});
}

TEST(ForwardKinematics, RootRotationTurnsTheWholeChain) {
  // Root Zrotation 90: the chain along +x now points along +y.
  const RowMatrixXd world = WorldOf(Chain("XYZ", "0 0 5 90 0 0 0 0 0 0 0 0"));
  ExpectJoint(world, 0, 0, {0, 0, 5});
  ExpectJoint(world, 0, 1, {0, 10, 5});
  ExpectJoint(world, 0, 2, {0, 20, 5});
}

TEST(ForwardKinematics, AJointRotationMovesOnlyItsChildren) {
  // Upper's Zrotation 90 (its third channel in XYZ): Lower's offset turns to +y.
  const RowMatrixXd world = WorldOf(Chain("XYZ", "0 0 0 0 0 0 0 0 90 0 0 0"));
  ExpectJoint(world, 0, 1, {10, 0, 0});
  ExpectJoint(world, 0, 2, {10, 10, 0});
}

TEST(ForwardKinematics, RotationOrderIsTheChannelOrder) {
  // The same two angles, X 90 and Y 90, listed in two orders. Listed X then Y: Rx(90) Ry(90)
  // takes +x first to -z (Ry), then to +y (Rx). Listed Y then X: Ry(90) Rx(90) leaves +x to
  // Rx, then Ry takes it to -z.
  const RowMatrixXd xyz = WorldOf(Chain("XYZ", "0 0 0 0 0 0 90 90 0 0 0 0"));
  ExpectJoint(xyz, 0, 2, {10, 10, 0});
  const RowMatrixXd yxz = WorldOf(Chain("YXZ", "0 0 0 0 0 0 90 90 0 0 0 0"));
  ExpectJoint(yxz, 0, 2, {10, 0, -10});
}

TEST(ForwardKinematics, RotationsComposeDownTheChain) {
  // Root Zrotation 90 (+x -> +y), Upper Zrotation 90 (+x -> +y in the root's frame, so -x in
  // the world): Upper at (0, 10, 0), Lower 10 along -x from it.
  const RowMatrixXd world = WorldOf(Chain("XYZ", "0 0 0 90 0 0 0 0 90 0 0 0"));
  ExpectJoint(world, 0, 1, {0, 10, 0});
  ExpectJoint(world, 0, 2, {-10, 10, 0});
}

TEST(ForwardKinematics, PositionChannelsReplaceTheOffset) {
  // A root with an OFFSET and position channels sits at its channels' values; a joint with
  // position channels of its own (as some exporters write every joint) likewise.
  const std::string bvh =
      "HIERARCHY\nROOT Hips\n{\n OFFSET 100 100 100\n"
      " CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      " JOINT Arm\n {\n  OFFSET 10 0 0\n"
      "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      "  End Site\n  {\n   OFFSET 1 0 0\n  }\n }\n}\n"
      "MOTION\nFrames: 2\nFrame Time: 0.04\n"
      "1 2 3 0 0 0 10 0 0 0 0 0\n"
      "1 2 3 90 0 0 0 0 7 0 0 0\n";
  const RowMatrixXd world = WorldOf(bvh);
  ASSERT_EQ(world.rows(), 2);
  ExpectJoint(world, 0, 0, {1, 2, 3});
  ExpectJoint(world, 0, 1, {11, 2, 3});
  // Frame 1: the root turned 90 about z, so Arm's (0, 0, 7) stays along z.
  ExpectJoint(world, 1, 0, {1, 2, 3});
  ExpectJoint(world, 1, 1, {1, 2, 10});
}

TEST(ForwardKinematics, EveryFrameIsItsOwn) {
  const std::string bvh = absl::StrCat(Chain("ZXY", "0 0 0 0 0 0 0 0 0 0 0 0"));
  // Three frames: the root walking along x while Upper turns about z.
  const std::string frames =
      "Frames: 3\nFrame Time: 0.04\n"
      "0 0 0 0 0 0 0 0 0 0 0 0\n"
      "5 0 0 0 0 0 90 0 0 0 0 0\n"
      "10 0 0 0 0 0 180 0 0 0 0 0\n";
  const std::string text = bvh.substr(0, bvh.find("Frames:")) + frames;
  const RowMatrixXd world = WorldOf(text);
  ASSERT_EQ(world.rows(), 3);
  ExpectJoint(world, 0, 2, {20, 0, 0});
  ExpectJoint(world, 1, 2, {15, 10, 0});
  ExpectJoint(world, 2, 2, {10, 0, 0});
}

}  // namespace
}  // namespace motiondb
