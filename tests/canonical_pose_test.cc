// Canonical-bones spaces (issue 40 item 3): a Bandai take and its re-rigged copy (other names,
// an extra spine joint, no toes, another rotation order and rest pose, 3-channel joints, another
// scale, Z up) have the same canonical poses and project to the same curve; such a space is
// stored and read back, refuses to rebuild rotations, and names the slots a skeleton lacks; a
// joint-rotation space is written as before.
#include "core/space/canonical_pose.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "core/motion/clip_mirror.h"
#include "core/motion/forward_kinematics.h"
#include "core/space/motion_space.h"
#include "core/space/space_serialization.h"
#include "testing/corpus_paths.h"
#include "testing/rerigged_copy.h"

namespace motiondb {
namespace {

std::optional<Clip> BandaiTake(const std::string& name) {
  const std::optional<std::filesystem::path> dir = testing::MocapDir();
  if (!dir) return std::nullopt;
  absl::StatusOr<BvhReadResult> read = ReadBvhFile((*dir / "bandai1" / name).string());
  if (!read.ok()) return std::nullopt;
  return read->clip;
}

TEST(CanonicalPoseTest, ReriggedCopyKeepsWorldPositionsTurnedAndScaled) {
  const std::optional<Clip> take = BandaiTake("dataset-1_walk_active_001.bvh");
  if (!take) GTEST_SKIP() << "../shared/mocap/bandai1 is absent; skipped";
  const absl::StatusOr<Clip> copy = testing::ReriggedCopy(*take);
  ASSERT_TRUE(copy.ok()) << copy.status();
  const RowMatrixXd original = ForwardKinematics(*take);
  const RowMatrixXd rerigged = ForwardKinematics(*copy);
  double largest = 0.0;
  for (const auto& [from, to] :
       std::vector<std::pair<std::string, std::string>>{{"Hips", "mixamorig:Hips"},
                                                        {"Hand_L", "mixamorig:LeftHand"},
                                                        {"Foot_R", "mixamorig:RightFoot"},
                                                        {"Head", "mixamorig:Head"}}) {
    const int a = take->skeleton().FindJoint(from);
    const int b = copy->skeleton().FindJoint(to);
    ASSERT_GE(b, 0) << to;
    for (int f = 0; f < take->frame_count(); ++f) {
      const Eigen::Vector3d want =
          testing::kRerigScale *
          (testing::RerigUpTurn() * Eigen::Vector3d(original.block<1, 3>(f, 3 * a).transpose()));
      largest = std::max(largest, (rerigged.block<1, 3>(f, 3 * b).transpose() - want).norm());
    }
  }
  // The BVH text keeps 6 decimals of each angle: a hand 80 cm from the hips moves < 0.01 units.
  EXPECT_LT(largest, 0.05 * testing::kRerigScale);
  EXPECT_EQ(copy->skeleton().FindJoint("mixamorig:LeftToeBase"), -1);
}

TEST(CanonicalPoseTest, TakeAndReriggedCopyGiveTheSamePoses) {
  const std::optional<Clip> take = BandaiTake("dataset-1_walk_active_001.bvh");
  if (!take) GTEST_SKIP() << "../shared/mocap/bandai1 is absent; skipped";
  const absl::StatusOr<Clip> copy = testing::ReriggedCopy(*take);
  ASSERT_TRUE(copy.ok()) << copy.status();
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(take->skeleton());
  const absl::StatusOr<HumanoidMap> copy_map = MapHumanoid(copy->skeleton());
  ASSERT_TRUE(map.ok() && copy_map.ok());
  ASSERT_TRUE(CheckCanonicalMap(*copy_map, "copy").ok());
  const PoseOptions options;
  const RowMatrixXd a = CanonicalPoses(*take, *map, options);
  const RowMatrixXd b = CanonicalPoses(*copy, *copy_map, options);
  ASSERT_EQ(a.rows(), b.rows());
  ASSERT_EQ(a.cols(), CanonicalPoseDims(options));
  // Unit directions agree to within the text's rounding; the walk itself spans about 1 per bone.
  EXPECT_LT((a.leftCols(3 * kCanonicalBoneCount) - b.leftCols(3 * kCanonicalBoneCount))
                .cwiseAbs()
                .maxCoeff(),
            1e-3);
  EXPECT_LT((a.rightCols(3) - b.rightCols(3)).cwiseAbs().maxCoeff(), 1e-2);
  // A walk: forwards (the last column, leg lengths/s) by more than half a leg length a second.
  EXPECT_GT(a.col(a.cols() - 1).mean(), 0.5);
}

// `clip` with its whole world turned by `turn`: its root's rotation and translation turned.
Clip Turned(const Clip& clip, const Eigen::Matrix3d& turn) {
  EXPECT_EQ(clip.skeleton().position_slot(0), 0) << "the root must hold the first translation";
  RowMatrixXd rotations = clip.rotations();
  RowMatrixXd positions = clip.positions();
  const Quat q_turn(turn);
  for (int f = 0; f < clip.frame_count(); ++f) {
    const Quat root = q_turn * clip.rotation(f, 0);
    rotations.block<1, 4>(f, 0) << root.w(), root.x(), root.y(), root.z();
    positions.block<1, 3>(f, 0) = (turn * positions.block<1, 3>(f, 0).transpose()).transpose();
  }
  absl::StatusOr<Clip> turned =
      Clip::Create(clip.shared_skeleton(), clip.frame_time(), rotations, positions);
  EXPECT_TRUE(turned.ok()) << turned.status();
  return *std::move(turned);
}

// A real walk with turns (CMU 01_01: a T-pose rest, so its rest pose is the mirror's
// reference): mirroring its canonical poses gives the canonical poses of the clip mirrored
// joint by joint (clip_mirror.h), bones, yaw rate and velocity, and mirroring twice gives them
// back.
TEST(CanonicalPoseTest, MirroredPosesAreThePosesOfTheMirroredClip) {
  const std::optional<std::filesystem::path> dir = testing::MocapDir();
  if (!dir) GTEST_SKIP() << "../shared/mocap is absent; skipped";
  const absl::StatusOr<BvhReadResult> read =
      ReadBvhFile((*dir / "cmu" / "01_01_motionbuilder.bvh").string());
  ASSERT_TRUE(read.ok()) << read.status();
  const Clip& clip = read->clip;
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(clip.skeleton());
  ASSERT_TRUE(map.ok());
  const absl::StatusOr<SkeletonMirror> mirror = MakeSkeletonMirror(clip.skeleton(), *map);
  ASSERT_TRUE(mirror.ok()) << mirror.status();
  absl::StatusOr<Clip> mirrored = MirrorClip(clip, *mirror);
  ASSERT_TRUE(mirrored.ok()) << mirrored.status();
  // The reference pose's lateral axis leans about a degree off the horizontal (CMU's rest pose
  // is not quite upright), so its mirror leans the world by twice that; canonical poses mirror
  // through a vertical plane. The two reflections' product, a turn, stands the mirror up.
  const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d lateral = mirror->lateral;
  const Eigen::Vector3d level = (lateral - lateral.dot(up) * up).normalized();
  const Eigen::Matrix3d reflect = Eigen::Matrix3d::Identity() - 2 * lateral * lateral.transpose();
  const Eigen::Matrix3d reflect_level = Eigen::Matrix3d::Identity() - 2 * level * level.transpose();
  mirrored = Turned(*mirrored, reflect_level * reflect);
  const absl::StatusOr<HumanoidMap> mirrored_map = MapHumanoid(mirrored->skeleton());
  ASSERT_TRUE(mirrored_map.ok());

  const PoseOptions options;
  const RowMatrixXd poses = CanonicalPoses(clip, *map, options);
  const RowMatrixXd want = CanonicalPoses(*mirrored, *mirrored_map, options);
  RowMatrixXd got = poses;
  ASSERT_TRUE(MirrorCanonicalPoses(options, &got).ok());
  ASSERT_EQ(got.rows(), want.rows());
  EXPECT_LT((got - want).cwiseAbs().maxCoeff(), 1e-9);
  // The mirror is not the clip: the walk turns, its arms swing out of step.
  EXPECT_GT((got - poses).cwiseAbs().maxCoeff(), 0.5);
  EXPECT_GT(poses.col(3 * kCanonicalBoneCount).cwiseAbs().maxCoeff(), 0.1);  // it turns
  ASSERT_TRUE(MirrorCanonicalPoses(options, &got).ok());
  EXPECT_LT((got - poses).cwiseAbs().maxCoeff(), 1e-12);

  RowMatrixXd narrow = poses.leftCols(10);
  EXPECT_EQ(MirrorCanonicalPoses(options, &narrow).code(), absl::StatusCode::kInvalidArgument);
}

TEST(CanonicalPoseTest, SpaceOverTwoRigsProjectsBothAlikeAndRoundTrips) {
  const std::optional<Clip> walk = BandaiTake("dataset-1_walk_active_001.bvh");
  const std::optional<Clip> bow = BandaiTake("dataset-1_bow_active_001.bvh");
  if (!walk || !bow) GTEST_SKIP() << "../shared/mocap/bandai1 is absent; skipped";
  const absl::StatusOr<Clip> copy = testing::ReriggedCopy(*bow);
  ASSERT_TRUE(copy.ok()) << copy.status();
  SpaceOptions options;
  options.representation = SpaceRepresentation::kCanonicalBones;
  const absl::StatusOr<MotionSpace> space =
      MotionSpace::Build(std::vector<TrainingClip>{{"walk", *walk, std::nullopt},
                                                   {"bow rerigged", *copy, std::nullopt}},
                         options);
  ASSERT_TRUE(space.ok()) << space.status();
  EXPECT_TRUE(space->canonical());
  EXPECT_EQ(space->dims(), 3 * kCanonicalBoneCount + 3);
  const absl::StatusOr<RowMatrixXd> own = space->ProjectClip(*bow);
  const absl::StatusOr<RowMatrixXd> other = space->ProjectClip(*copy);
  ASSERT_TRUE(own.ok() && other.ok());
  EXPECT_LT((*own - *other).rowwise().norm().maxCoeff(), 0.02);
  const absl::StatusOr<RowMatrixXd> walked = space->ProjectClip(*walk);
  ASSERT_TRUE(walked.ok());
  // Their common frames (the walk and the bow differ in length).
  const Eigen::Index common = std::min(walked->rows(), own->rows());
  EXPECT_GT((walked->topRows(common) - own->topRows(common)).rowwise().norm().mean(), 0.2);

  const absl::StatusOr<std::vector<ReconstructionError>> errors =
      space->RepresentationalError(std::vector<TrainingClip>{{"walk", *walk, std::nullopt}});
  ASSERT_TRUE(errors.ok()) << errors.status();
  EXPECT_NEAR(errors->back().max_rad, 0.0, 1e-6);  // every dimension rebuilds every direction

  const absl::StatusOr<RowMatrixXd> rotations = space->Reconstruct(own->topRows(2));
  EXPECT_EQ(rotations.status().code(), absl::StatusCode::kFailedPrecondition);

  const std::string bytes = SerializeSpace(*space);
  EXPECT_EQ(bytes[8], static_cast<char>(kSpaceFormatVersion));
  const absl::StatusOr<MotionSpace> read = ParseSpace(bytes);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_TRUE(read->canonical());
  const absl::StatusOr<RowMatrixXd> again = read->ProjectClip(*copy);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, *other);
}

TEST(CanonicalPoseTest, JointRotationSpacesAreWrittenAsBefore) {
  const std::optional<Clip> walk = BandaiTake("dataset-1_walk_active_001.bvh");
  if (!walk) GTEST_SKIP() << "../shared/mocap/bandai1 is absent; skipped";
  const absl::StatusOr<MotionSpace> space =
      MotionSpace::Build(std::vector<TrainingClip>{{"walk", *walk, std::nullopt}});
  ASSERT_TRUE(space.ok()) << space.status();
  EXPECT_FALSE(space->canonical());
  const std::string bytes = SerializeSpace(*space);
  EXPECT_EQ(bytes[8], 2);  // the version builds before canonical spaces wrote and read
  const absl::StatusOr<MotionSpace> read = ParseSpace(bytes);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(SerializeSpace(*read), bytes);
  EXPECT_TRUE(read->Reconstruct(*space->ProjectClip(*walk)).ok());
}

TEST(CanonicalPoseTest, SkeletonWithoutArmsIsRefusedNamingTheSlots) {
  std::vector<Joint> joints(4);
  joints[0] = {"Hips", -1, Eigen::Vector3d::Zero(), {}, std::nullopt};
  joints[1] = {"LeftUpLeg", 0, Eigen::Vector3d(1, 0, 0), {}, std::nullopt};
  joints[2] = {"RightUpLeg", 0, Eigen::Vector3d(-1, 0, 0), {}, std::nullopt};
  joints[3] = {"Head", 0, Eigen::Vector3d(0, 5, 0), {}, std::nullopt};
  const absl::StatusOr<Skeleton> skeleton = Skeleton::Create(joints);
  ASSERT_TRUE(skeleton.ok()) << skeleton.status();
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(*skeleton);
  ASSERT_TRUE(map.ok());
  const absl::Status status = CheckCanonicalMap(*map, "7");
  EXPECT_EQ(status.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(status.message().find("LeftHand"), std::string::npos) << status;
  EXPECT_NE(status.message().find("skeleton 7"), std::string::npos) << status;
  EXPECT_EQ(status.message().find("Head"), std::string::npos) << status;
}

TEST(CanonicalPoseTest, RepresentationNamesRoundTrip) {
  for (const SpaceRepresentation r :
       {SpaceRepresentation::kJointRotations, SpaceRepresentation::kCanonicalBones}) {
    EXPECT_EQ(*ParseSpaceRepresentation(SpaceRepresentationName(r)), r);
  }
  EXPECT_FALSE(ParseSpaceRepresentation("positions").ok());
}

}  // namespace
}  // namespace motiondb
