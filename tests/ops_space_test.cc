// The operators that leave the space (core/ops): a clip into a space and back out as joint
// rotations with its placement, reconstruction error against n (thesis 3.3.4), MC-LERP against
// SLERP (4.1) and the joint constraints applied after unprojection (5.7).
#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/ops/interpolation.h"
#include "core/ops/joint_constraints.h"
#include "core/ops/reconstruction.h"
#include "core/ops/space_motion.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;

MotionSpace BuildSpace(const Clip& clip, SpaceOptions options = {}) {
  options.sample_rate = clip.fps();  // no resampling: every frame is a training frame
  absl::StatusOr<MotionSpace> space = MotionSpace::Build({{"train", clip, std::nullopt}}, options);
  EXPECT_TRUE(space.ok()) << space.status();
  return *std::move(space);
}

double AngleAt(const RowMatrixXd& rotations, Eigen::Index frame, int joint, const Quat& other) {
  const auto q = rotations.block<1, 4>(frame, 4 * joint);
  return AngleBetween(Quat(q[0], q[1], q[2], q[3]), other);
}

Quat QuatAt(const RowMatrixXd& rotations, Eigen::Index frame, int joint) {
  const auto q = rotations.block<1, 4>(frame, 4 * joint);
  return Quat(q[0], q[1], q[2], q[3]);
}

class OpsSpaceTest : public ::testing::TestWithParam<bool> {
 protected:
  OpsSpaceTest()
      : skeleton_(testing::HumanoidSkeleton(/*still_root=*/true)),
        clip_(testing::SyntheticClip(skeleton_, {.frames = 90, .turn_rate = 0.7, .seed = 3})),
        space_(BuildSpace(clip_, {.pose = {.remove_heading = GetParam()}})),
        motion_(*EnterSpace(space_, clip_)) {}

  std::shared_ptr<const Skeleton> skeleton_;
  Clip clip_;
  MotionSpace space_;
  SpaceMotion motion_;
};

INSTANTIATE_TEST_SUITE_P(FacingRemovedOrKept, OpsSpaceTest, ::testing::Bool());

TEST_P(OpsSpaceTest, AClipLeavesTheSpaceAsItEnteredWithEveryDimension) {
  ASSERT_EQ(motion_.coordinates.rows(), clip_.frame_count());
  ASSERT_EQ(motion_.placement.frames(), clip_.frame_count());
  const absl::StatusOr<RowMatrixXd> pose = space_.Reconstruct(motion_.coordinates);
  ASSERT_TRUE(pose.ok()) << pose.status();
  const absl::StatusOr<Clip> out = ToClip(
      space_, skeleton_, PlaceRotations(space_, *pose, motion_.placement), motion_.placement);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_LT(testing::MaxRotationError(*out, clip_), 1e-9);
  EXPECT_EQ(out->positions(), clip_.positions());

  // And as BVH with the source's hierarchy and channel orders.
  const absl::StatusOr<std::string> bvh = WriteBvh(*out);
  ASSERT_TRUE(bvh.ok()) << bvh.status();
  const absl::StatusOr<BvhReadResult> read = ReadBvh(*bvh);
  ASSERT_TRUE(read.ok()) << read.status();
  // The writer lists joints depth first, the synthetic skeleton side by side: match by name.
  ASSERT_EQ(read->clip.skeleton().joint_count(), skeleton_->joint_count());
  ASSERT_EQ(read->clip.frame_count(), clip_.frame_count());
  for (int j = 0; j < skeleton_->joint_count(); ++j) {
    const int k = read->clip.skeleton().FindJoint(skeleton_->joint(j).name);
    ASSERT_GE(k, 0);
    for (int f = 0; f < clip_.frame_count(); ++f) {
      EXPECT_LT(AngleBetween(read->clip.rotation(f, k), clip_.rotation(f, j)), 1e-5);
    }
  }
}

TEST_P(OpsSpaceTest, ReconstructionErrorFallsWithDimensionsToZeroAtAll) {
  const absl::StatusOr<Reconstruction> full =
      Reconstruct(space_, motion_.coordinates, motion_.rotations, {.error_curve = true});
  ASSERT_TRUE(full.ok()) << full.status();
  EXPECT_EQ(full->dims, space_.dims());
  EXPECT_LT(full->overall.max_rad, 1e-9);
  ASSERT_EQ(full->joints.size(), static_cast<size_t>(skeleton_->joint_count()));
  ASSERT_EQ(full->curve.size(), static_cast<size_t>(space_.dims()));
  EXPECT_GT(full->curve.front().mean_rad, 0.05);
  for (size_t n = 1; n < full->curve.size(); ++n) {
    // Each dimension adds an orthogonal share of the pose; the angles follow within rounding.
    EXPECT_LE(full->curve[n].mean_rad, full->curve[n - 1].mean_rad + 1e-3) << "n = " << n + 1;
  }
  EXPECT_LT(full->curve.back().max_rad, 1e-9);

  const absl::StatusOr<Reconstruction> three =
      Reconstruct(space_, motion_.coordinates, motion_.rotations, {.dims = 3});
  ASSERT_TRUE(three.ok()) << three.status();
  EXPECT_EQ(three->coordinates.cols(), 3);
  EXPECT_NEAR(three->overall.mean_rad, full->curve[2].mean_rad, 1e-12);
  double mean_of_joints = 0.0;
  for (const AngleError& joint : three->joints) mean_of_joints += joint.mean_rad;
  EXPECT_NEAR(mean_of_joints / three->joints.size(), three->overall.mean_rad, 1e-12);
  // The still root never moves, and its reconstruction never errs.
  EXPECT_LT(three->joints[0].max_rad, 1e-9);

  const absl::Status bad =
      Reconstruct(space_, motion_.coordinates, motion_.rotations, {.dims = space_.dims() + 1})
          .status();
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.message(), HasSubstr("dims"));
  EXPECT_FALSE(Reconstruct(space_, motion_.coordinates, motion_.rotations.topRows(3)).ok());
}

TEST_P(OpsSpaceTest, McLerpAndSlerpHitBothPosesAndDifferLittleBetween) {
  RowMatrixXd poses(2, space_.dims());
  poses << motion_.coordinates.row(10), motion_.coordinates.row(40);
  RowMatrixXd rotations(2, motion_.rotations.cols());
  rotations << motion_.rotations.row(10), motion_.rotations.row(40);
  const absl::StatusOr<Interpolation> result = InterpolatePoses(space_, poses, rotations);
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->t.size(), 11u);
  for (const Eigen::Index end : {Eigen::Index{0}, Eigen::Index{10}}) {
    const Eigen::Index source = end == 0 ? 10 : 40;
    for (int j = 0; j < skeleton_->joint_count(); ++j) {
      const Quat original = QuatAt(motion_.rotations, source, j);
      EXPECT_LT(AngleAt(result->mc_lerp, end, j, original), 1e-9);
      EXPECT_LT(AngleAt(result->slerp, end, j, original), 1e-9);
    }
    EXPECT_LT(result->difference[end].max_rad, 1e-9);
    EXPECT_LT(result->curve_distance[end], 1e-6);
  }
  // Between them the two methods part, by less than the poses themselves differ (4.1).
  AngleError between;
  AngleErrors(rotations.row(0), rotations.row(1), nullptr, &between);
  EXPECT_GT(result->difference[5].max_rad, 1e-6);
  EXPECT_LT(result->overall.max_rad, 0.25 * between.max_rad);
  // SLERP's midpoint takes every joint halfway along its arc.
  for (int j = 0; j < skeleton_->joint_count(); ++j) {
    EXPECT_NEAR(AngleAt(result->slerp, 5, j, QuatAt(rotations, 0, j)),
                AngleAt(result->slerp, 5, j, QuatAt(rotations, 1, j)), 1e-9);
  }
}

TEST_P(OpsSpaceTest, InterpolationRefusesBadParameters) {
  const RowMatrixXd poses = motion_.coordinates.topRows(2);
  const RowMatrixXd rotations = motion_.rotations.topRows(2);
  const auto message = [&](const InterpolationOptions& options) {
    return std::string(InterpolatePoses(space_, poses, rotations, options).status().message());
  };
  EXPECT_THAT(message({.t = {0.5, 1.5}}), HasSubstr("t[1]"));
  EXPECT_THAT(message({.t = {std::nan("")}}), HasSubstr("t[0]"));
  EXPECT_THAT(message({.steps = 1}), HasSubstr("steps"));
  EXPECT_THAT(message({.dims = 0}), HasSubstr("dims"));
  EXPECT_THAT(std::string(InterpolatePoses(space_, motion_.coordinates.topRows(3),
                                           motion_.rotations.topRows(3))
                              .status()
                              .message()),
              HasSubstr("two poses"));
}

TEST_P(OpsSpaceTest, FrozenJointsKeepTheSourceAndLimitsBoundTheEdit) {
  const int arm = skeleton_->FindJoint("UpperArm_L");
  const int leg = skeleton_->FindJoint("UpperLeg_R");
  const RowMatrixXd& source = motion_.rotations;
  // An exaggerated pose: every coordinate doubled.
  const absl::StatusOr<RowMatrixXd> edited = space_.Reconstruct(2.0 * motion_.coordinates);
  ASSERT_TRUE(edited.ok());

  RowMatrixXd frozen = *edited;
  ASSERT_TRUE(
      ApplyJointConstraints(space_, {.edit_weights = {{"UpperArm_L", 0.0}}}, source, &frozen).ok());
  RowMatrixXd half = *edited;
  ASSERT_TRUE(
      ApplyJointConstraints(space_, {.edit_weights = {{"UpperArm_L", 0.5}}}, source, &half).ok());
  for (Eigen::Index f = 0; f < source.rows(); ++f) {
    EXPECT_LT(AngleAt(frozen, f, arm, QuatAt(source, f, arm)), 1e-9);
    EXPECT_EQ(frozen.row(f).segment<4>(4 * leg), edited->row(f).segment<4>(4 * leg));
    EXPECT_NEAR(AngleAt(half, f, arm, QuatAt(source, f, arm)),
                AngleAt(half, f, arm, QuatAt(*edited, f, arm)), 1e-9);
  }

  const auto reference = [&](int joint) {
    const auto r = space_.data().references.row(joint);
    return Quat(r[0], r[1], r[2], r[3]);
  };
  RowMatrixXd limited = *edited;
  ASSERT_TRUE(ApplyJointConstraints(space_,
                                    {.max_angles = {{"UpperArm_L", 0.1}}, .source_margin = 0.0},
                                    source, &limited)
                  .ok());
  double reach = 0.0;  // the source's own largest angle from the leg's reference
  for (Eigen::Index f = 0; f < source.rows(); ++f) {
    reach = std::max(reach, AngleAt(source, f, leg, reference(leg)));
  }
  for (Eigen::Index f = 0; f < source.rows(); ++f) {
    EXPECT_LE(AngleAt(limited, f, arm, reference(arm)), 0.1 + 1e-9);
    EXPECT_LE(AngleAt(limited, f, leg, reference(leg)), reach + 1e-9);
  }
  EXPECT_GT(AngleAt(*edited, 0, arm, reference(arm)) + AngleAt(*edited, 30, arm, reference(arm)),
            0.2);  // the limit had something to clamp

  const auto message = [&](const JointConstraints& constraints) {
    RowMatrixXd copy = *edited;
    return std::string(ApplyJointConstraints(space_, constraints, source, &copy).message());
  };
  EXPECT_THAT(message({.edit_weights = {{"Tail", 0.5}}}), HasSubstr("edit_weights[Tail]"));
  EXPECT_THAT(message({.edit_weights = {{"Head", 1.5}}}), HasSubstr("edit_weights[Head]"));
  EXPECT_THAT(message({.max_angles = {{"Head", -1}}}), HasSubstr("max_angles[Head]"));
  EXPECT_THAT(message({.source_margin = std::nan("")}), HasSubstr("source_margin"));
}

}  // namespace
}  // namespace motiondb
