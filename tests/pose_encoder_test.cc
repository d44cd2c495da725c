// Pose vectors (SPEC §2.5-2.6): the batched encoder against the scalar log map, and its inverse.
#include "core/space/pose_encoder.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "tests/synthetic_motion.h"

namespace motiondb {
namespace {

constexpr double kPi = std::numbers::pi;

// Rotations chosen to reach every branch of the batched log map: identity, tiny angles, both
// sides of the pi/4 and pi/2 reductions, angles near pi, w < 0, and random ones.
std::vector<Quat> Probes() {
  std::vector<Quat> probes = {Quat::Identity(), Quat(-1, 0, 0, 0)};
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  for (const double angle : {1e-15, 1e-12, 1e-9, 1e-4, 0.5, 2 * std::atan(0.41421356237309503),
                             2 * std::atan(0.41421356237309506), kPi / 2 - 1e-12, kPi / 2,
                             kPi / 2 + 1e-12, 2.0, 3.0, kPi - 1e-9, kPi}) {
    const Quat q(Eigen::AngleAxisd(angle, axis));
    probes.push_back(q);
    probes.push_back(Quat(-q.w(), -q.x(), -q.y(), -q.z()));
  }
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 500; ++i) {
    probes.push_back(
        Quat(normal(random), normal(random), normal(random), normal(random)).normalized());
  }
  return probes;
}

TEST(PoseEncoderTest, BatchedLogMapMatchesTheScalarOne) {
  const std::vector<Quat> probes = Probes();
  // Three joints with different references, one probe per frame for each.
  const Quat references[] = {Quat::Identity(),
                             Quat(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())),
                             Quat(Eigen::AngleAxisd(-2.5, Eigen::Vector3d(1, 1, 0).normalized()))};
  RowMatrixXd reference_rows(3, 4);
  for (int j = 0; j < 3; ++j) {
    reference_rows.row(j) << references[j].w(), references[j].x(), references[j].y(),
        references[j].z();
  }
  PoseRotations pose{RowMatrixXd(probes.size(), 12), Eigen::VectorXd(), RowMatrixXd()};
  for (size_t f = 0; f < probes.size(); ++f) {
    for (int j = 0; j < 3; ++j) {
      const Quat q = references[j] * probes[(f + 13 * j) % probes.size()];
      pose.rotations.block<1, 4>(f, 4 * j) << q.w(), q.x(), q.y(), q.z();
    }
  }
  const RowMatrixXd poses = EncodePoses(pose, reference_rows);
  ASSERT_EQ(poses.cols(), 9);
  double worst = 0.0;
  for (Eigen::Index f = 0; f < poses.rows(); ++f) {
    for (int j = 0; j < 3; ++j) {
      const auto q = pose.rotations.block<1, 4>(f, 4 * j);
      const Eigen::Vector3d expected = LogMapAbout(Quat(q[0], q[1], q[2], q[3]), references[j]);
      const Eigen::Vector3d actual = poses.block<1, 3>(f, 3 * j).transpose();
      double error = (actual - expected).norm();
      // Half turns (w = 0) have two rotation vectors, v and -v; rounding may pick either.
      if (expected.norm() > kPi - 1e-6) error = std::min(error, (actual + expected).norm());
      worst = std::max(worst, error);
      EXPECT_LE((poses.block<1, 3>(f, 3 * j).norm()), kPi + 1e-12);
    }
  }
  EXPECT_LT(worst, 1e-13);

  // And back: every rotation returns, up to sign, with w >= 0.
  const RowMatrixXd decoded = DecodePoses(poses, reference_rows);
  for (Eigen::Index f = 0; f < poses.rows(); ++f) {
    for (int j = 0; j < 3; ++j) {
      const auto a = pose.rotations.block<1, 4>(f, 4 * j);
      const auto b = decoded.block<1, 4>(f, 4 * j);
      EXPECT_GE(b[0], 0.0);
      EXPECT_LT(AngleBetween(Quat(a[0], a[1], a[2], a[3]), Quat(b[0], b[1], b[2], b[3])), 1e-9);
    }
  }
}

TEST(PoseEncoderTest, DimensionsAndTheYawRateColumn) {
  EXPECT_EQ(PoseDims(22, {.root_velocity = false}), 67);
  EXPECT_EQ(PoseDims(22, {.remove_heading = false}), 66);
  EXPECT_FALSE(ValidatePoseOptions({.yaw_rate_window = 0}).ok());
  EXPECT_TRUE(ValidatePoseOptions({.yaw_rate_window = 1}).ok());

  const Clip clip = testing::SyntheticClip(testing::HumanoidSkeleton(/*still_root=*/true),
                                           {.frames = 30, .turn_rate = 2.0});
  const PoseRotations kept = ComputePoseRotations(clip, {.remove_heading = false});
  EXPECT_EQ(kept.rotations, clip.rotations());
  EXPECT_EQ(kept.yaw_rate.size(), 0);
  const PoseRotations removed = ComputePoseRotations(clip, {.root_velocity = false});
  ASSERT_EQ(removed.yaw_rate.size(), 30);
  const RowMatrixXd references = RowMatrixXd::Zero(clip.skeleton().joint_count(), 4).rowwise() +
                                 Eigen::RowVector4d(1, 0, 0, 0);
  const RowMatrixXd poses = EncodePoses(removed, references);
  ASSERT_EQ(poses.cols(), 3 * clip.skeleton().joint_count() + 1);
  EXPECT_EQ(poses.col(poses.cols() - 1), removed.yaw_rate);
  // The turn adds its rate to the pelvis's sway, frame by frame.
  const Clip straight = testing::SyntheticClip(testing::HumanoidSkeleton(/*still_root=*/true),
                                               {.frames = 30, .turn_rate = 0.0});
  const Eigen::VectorXd turn = removed.yaw_rate - ComputePoseRotations(straight, {}).yaw_rate;
  EXPECT_LT((turn.array() - 2.0).abs().maxCoeff(), 1e-9);
  EXPECT_EQ(poses.leftCols(3), RowMatrixXd::Zero(30, 3));  // the still root: placement only
}

}  // namespace
}  // namespace motiondb
