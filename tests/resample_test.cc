#include "core/motion/resample.h"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/clip_builder.h"

namespace motiondb {
namespace {

using testing::ChainSkeleton;
using testing::MakeClip;

constexpr double kOmega = 2.0;  // rad/s about Y: constant angular velocity
const Eigen::Vector3d kVelocity(0.5, 0.0, -1.5);

Quat TurnAt(double t) { return Quat(Eigen::AngleAxisd(kOmega * t, Eigen::Vector3d::UnitY())); }

// Constant-velocity motion, which slerp and lerp reproduce exactly at any rate.
Clip UniformMotion(double fps, int frames) {
  return MakeClip(
      ChainSkeleton(), frames, 1.0 / fps,
      [&](int f, int j) { return j == 1 ? TurnAt(f / fps) : Quat::Identity(); },
      [&](int f, int) { return Eigen::Vector3d(kVelocity * (f / fps)); });
}

TEST(Resample, UpsamplingInterpolatesExactlyOnUniformMotion) {
  const Clip clip = UniformMotion(30.0, 31);  // one second
  absl::StatusOr<Clip> fine = Resample(clip, 120.0);
  ASSERT_TRUE(fine.ok()) << fine.status();
  ASSERT_EQ(fine->frame_count(), 121);
  EXPECT_DOUBLE_EQ(fine->fps(), 120.0);
  for (int k = 0; k < fine->frame_count(); ++k) {
    const double t = k / 120.0;
    EXPECT_LT(AngleBetween(fine->rotation(k, 1), TurnAt(t)), 1e-12) << k;
    EXPECT_LT((fine->root_position(k) - kVelocity * t).norm(), 1e-12) << k;
  }
}

TEST(Resample, DownsamplingPicksTheSourceFrames) {
  const Clip clip = UniformMotion(120.0, 241);
  absl::StatusOr<Clip> coarse = Resample(clip, 30.0);
  ASSERT_TRUE(coarse.ok());
  ASSERT_EQ(coarse->frame_count(), 61);
  for (int k = 0; k < coarse->frame_count(); ++k) {
    EXPECT_EQ(coarse->rotations().row(k), clip.rotations().row(4 * k)) << k;
    EXPECT_EQ(coarse->positions().row(k), clip.positions().row(4 * k)) << k;
  }
}

TEST(Resample, SameRateIsTheIdentity) {
  const Clip clip = UniformMotion(30.0, 17);
  absl::StatusOr<Clip> same = Resample(clip, 30.0);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->rotations(), clip.rotations());
  EXPECT_EQ(same->positions(), clip.positions());
}

TEST(Resample, NonIntegerRatioEndsAtOrBeforeTheLastFrame) {
  const Clip clip = UniformMotion(30.0, 10);  // span 0.3 s
  absl::StatusOr<Clip> out = Resample(clip, 25.0);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->frame_count(), 8);  // t = 0, 0.04, ..., 0.28
  EXPECT_LT(AngleBetween(out->rotation(7, 1), TurnAt(0.28)), 1e-12);
}

TEST(Resample, TakesTheShorterArcWhenStoredSignsFlip) {
  // Consecutive frames hold q and -q' alternately: the same motion with flipped signs.
  const Clip clip = MakeClip(
      ChainSkeleton(), 11, 0.1,
      [](int f, int j) {
        Quat q = j == 1 ? TurnAt(f * 0.1) : Quat::Identity();
        if (f % 2) q.coeffs() = -q.coeffs();
        return q;
      },
      [](int, int) { return Eigen::Vector3d::Zero(); });
  absl::StatusOr<Clip> out = Resample(clip, 40.0);
  ASSERT_TRUE(out.ok());
  for (int k = 0; k < out->frame_count(); ++k) {
    EXPECT_LT(AngleBetween(out->rotation(k, 1), TurnAt(k / 40.0)), 1e-9) << k;
  }
}

TEST(Resample, RoundedFrameTimeKeepsTheLastFrame) {
  // 0.0333333 s is 1/30 rounded down: 120 frames span 3.9666627 s, just short of 119/30.
  const Clip clip = MakeClip(
      ChainSkeleton(), 120, 0.0333333, [](int f, int) { return TurnAt(f / 30.0); },
      [](int, int) { return Eigen::Vector3d::Zero(); });
  absl::StatusOr<Clip> out = Resample(clip, 30.0);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->frame_count(), 120);
  EXPECT_LT(AngleBetween(out->rotation(119, 1), clip.rotation(119, 1)), 1e-9);
}

TEST(Resample, SingleFrameStaysOneFrame) {
  absl::StatusOr<Clip> out = Resample(UniformMotion(30.0, 1), 120.0);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->frame_count(), 1);
}

TEST(Resample, ThreadsMakeTheSameFrames) {
  const Clip clip = testing::MakeClip(
      ChainSkeleton(), 700, 1.0 / 30,
      [](int f, int j) {
        return Quat(Eigen::AngleAxisd(0.05 * f * (j + 1), Eigen::Vector3d(1, 2, 0).normalized()));
      },
      [](int f, int) { return Eigen::Vector3d(std::sin(0.1 * f), f, 0); });
  const absl::StatusOr<Clip> one = Resample(clip, 119.0, 1);
  ASSERT_TRUE(one.ok()) << one.status();
  ASSERT_GT(one->frame_count(), 2000);  // several pieces of 256 frames
  for (const int threads : {2, 3, 8}) {
    const absl::StatusOr<Clip> several = Resample(clip, 119.0, threads);
    ASSERT_TRUE(several.ok()) << several.status();
    EXPECT_EQ(several->rotations(), one->rotations()) << threads << " threads";
    EXPECT_EQ(several->positions(), one->positions()) << threads << " threads";
  }
}

TEST(Resample, RejectsBadRates) {
  const Clip clip = UniformMotion(30.0, 5);
  for (double rate : std::vector<double>{0.0, -30.0, NAN, INFINITY, 1e9}) {
    EXPECT_EQ(Resample(clip, rate).status().code(), absl::StatusCode::kInvalidArgument) << rate;
  }
}

}  // namespace
}  // namespace motiondb
