// Facing removal (SPEC §2.4): the pelvis, the heading of its global orientation, the yaw rate.
#include "core/space/heading.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "tests/clip_builder.h"
#include "tests/synthetic_motion.h"

namespace motiondb {
namespace {

constexpr double kPi = std::numbers::pi;

Quat AxisAngle(double angle, const Eigen::Vector3d& axis) {
  return Quat(Eigen::AngleAxisd(angle, axis));
}

// The humanoid turning steadily at `rate` rad/s for `seconds` at 30 fps, every other joint still.
Clip SteadyTurn(bool still_root, double rate, double seconds) {
  const auto skeleton = testing::HumanoidSkeleton(still_root);
  const int pelvis = skeleton->FindJoint("Hips");
  return testing::MakeClip(
      skeleton, static_cast<int>(seconds * 30) + 1, 1.0 / 30,
      [&](int f, int j) {
        if (j != pelvis) return Quat::Identity();
        return AxisAngle(rate * f / 30.0, Eigen::Vector3d::UnitY()) *
               AxisAngle(kPi / 2, Eigen::Vector3d::UnitZ());
      },
      [](int, int) { return Eigen::Vector3d(0, 90, 0); });
}

TEST(HeadingTest, PelvisIsTheFirstBranchingJoint) {
  const auto bandai_like = testing::HumanoidSkeleton(/*still_root=*/true);
  EXPECT_EQ(FindPelvis(*bandai_like), bandai_like->FindJoint("Hips"));
  EXPECT_EQ(FindPelvis(*bandai_like), 1);
  EXPECT_EQ(FindPelvis(*testing::HumanoidSkeleton(/*still_root=*/false)), 0);
  EXPECT_EQ(FindPelvis(*testing::ChainSkeleton()), 0);  // never branches: the root
}

TEST(HeadingTest, HeadingIsTheTwistAboutTheVerticalAxis) {
  for (const double yaw : {-3.0, -1.0, 0.0, 0.5, 2.5}) {
    for (const double tilt : {0.0, 0.3, -1.2}) {
      const Quat global =
          AxisAngle(yaw, Eigen::Vector3d::UnitY()) * AxisAngle(tilt, Eigen::Vector3d::UnitX());
      const Quat heading = HeadingOf(global);
      EXPECT_LT(AngleBetween(heading, AxisAngle(yaw, Eigen::Vector3d::UnitY())), 1e-12)
          << "yaw " << yaw << " tilt " << tilt;
      EXPECT_GE(heading.w(), 0.0);
      EXPECT_DOUBLE_EQ(heading.x(), 0.0);
      EXPECT_DOUBLE_EQ(heading.z(), 0.0);
      const Quat flipped(-global.w(), -global.x(), -global.y(), -global.z());
      EXPECT_LT(AngleBetween(HeadingOf(flipped), heading), 1e-12);
    }
  }
  // Upside down about X: no vertical twist to speak of.
  EXPECT_TRUE(HeadingOf(AxisAngle(kPi, Eigen::Vector3d::UnitX())).isApprox(Quat::Identity()));
}

TEST(HeadingTest, RemovalClearsTheRootChainAndUnwrapsTheYaw) {
  // Ten seconds at 1 rad/s: more than one full turn, so the yaw must unwrap.
  const Clip clip = SteadyTurn(/*still_root=*/true, 1.0, 10.0);
  RowMatrixXd rotations = clip.rotations();
  const Eigen::VectorXd yaw = RemoveHeading(clip.skeleton(), &rotations);
  ASSERT_EQ(yaw.size(), clip.frame_count());
  for (int f = 0; f < clip.frame_count(); ++f) {
    EXPECT_NEAR(yaw[f] - yaw[0], f / 30.0, 1e-9) << "frame " << f;
    // Root: identity; pelvis: only its rest frame (90 degrees about Z) is left.
    EXPECT_TRUE((rotations.block<1, 4>(f, 0).isApprox(Eigen::RowVector4d(1, 0, 0, 0))));
    const auto p = rotations.block<1, 4>(f, 4);
    EXPECT_LT(
        AngleBetween(Quat(p[0], p[1], p[2], p[3]), AxisAngle(kPi / 2, Eigen::Vector3d::UnitZ())),
        1e-9);
  }
  // Joints below the pelvis are untouched.
  EXPECT_EQ(rotations.rightCols(rotations.cols() - 8),
            clip.rotations().rightCols(rotations.cols() - 8));
  const Eigen::VectorXd rate = YawRate(yaw, 30.0, 5);
  EXPECT_LT((rate.array() - 1.0).abs().maxCoeff(), 1e-9);
}

TEST(HeadingTest, TurningThePelvisOnlyShiftsTheYaw) {
  for (const bool still_root : {true, false}) {
    const Clip clip =
        testing::SyntheticClip(testing::HumanoidSkeleton(still_root), {.turn_rate = 0.7});
    const Clip turned = testing::TurnedClip(clip, kPi / 2);
    RowMatrixXd a = clip.rotations();
    RowMatrixXd b = turned.rotations();
    const Eigen::VectorXd yaw_a = RemoveHeading(clip.skeleton(), &a);
    const Eigen::VectorXd yaw_b = RemoveHeading(turned.skeleton(), &b);
    double worst = 0.0;
    for (int f = 0; f < clip.frame_count(); ++f) {
      for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
        const auto qa = a.block<1, 4>(f, 4 * j);
        const auto qb = b.block<1, 4>(f, 4 * j);
        worst = std::max(worst, AngleBetween(Quat(qa[0], qa[1], qa[2], qa[3]),
                                             Quat(qb[0], qb[1], qb[2], qb[3])));
      }
      EXPECT_NEAR(std::remainder(yaw_b[f] - yaw_a[f] - kPi / 2, 2 * kPi), 0.0, 1e-9);
    }
    EXPECT_LT(worst, 1e-9) << "still_root " << still_root;
    EXPECT_LT((YawRate(yaw_a, 60, 5) - YawRate(yaw_b, 60, 5)).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(HeadingTest, YawRateDifferentiatesAndSmooths) {
  EXPECT_EQ(YawRate(Eigen::VectorXd::Constant(1, 2.0), 30, 5), Eigen::VectorXd::Zero(1));
  Eigen::VectorXd two(2);
  two << 0.0, 0.1;
  EXPECT_TRUE(YawRate(two, 30, 5).isApprox(Eigen::VectorXd::Constant(2, 3.0)));

  // yaw = t^2 at 10 fps: central differences give exactly 2t; averaging a linear function over
  // a centred window changes nothing away from the ends.
  Eigen::VectorXd yaw(50);
  for (int k = 0; k < 50; ++k) yaw[k] = (k / 10.0) * (k / 10.0);
  const Eigen::VectorXd raw = YawRate(yaw, 10, 1);
  const Eigen::VectorXd smooth = YawRate(yaw, 10, 5);
  for (int k = 3; k < 47; ++k) {
    EXPECT_NEAR(raw[k], 2 * k / 10.0, 1e-9);
    EXPECT_NEAR(smooth[k], 2 * k / 10.0, 1e-9);
  }

  // Jitter with a period of 4 frames is damped five-fold by a 5-frame window.
  Eigen::VectorXd jitter(40);
  for (int k = 0; k < 40; ++k) jitter[k] = 0.01 * std::sin(kPi * k / 2);
  EXPECT_LT(YawRate(jitter, 30, 5).segment(5, 30).cwiseAbs().maxCoeff(),
            YawRate(jitter, 30, 1).segment(5, 30).cwiseAbs().maxCoeff() / 3 + 1e-12);
}

}  // namespace
}  // namespace motiondb
