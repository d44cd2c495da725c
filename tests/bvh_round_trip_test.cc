// read(write(x)) reproduces every joint rotation within 1e-6 rad and position within 1e-6
// relative, with the original hierarchy and channel orders.
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "tests/clip_builder.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

constexpr double kRotationTolerance = 1e-6;
constexpr double kPositionTolerance = 1e-6;

void ExpectSameHierarchy(const Skeleton& a, const Skeleton& b) {
  ASSERT_EQ(a.joint_count(), b.joint_count());
  for (int j = 0; j < a.joint_count(); ++j) {
    const Joint& x = a.joint(j);
    const Joint& y = b.joint(j);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.parent, y.parent);
    EXPECT_EQ(x.channels, y.channels) << x.name;
    EXPECT_LT((x.offset - y.offset).norm(), 1e-9 * (1 + x.offset.norm())) << x.name;
    ASSERT_EQ(x.end_site.has_value(), y.end_site.has_value()) << x.name;
    if (x.end_site) {
      EXPECT_LT((*x.end_site - *y.end_site).norm(), 1e-9 * (1 + x.end_site->norm()));
    }
  }
}

// Writes, reads back, and compares with `expected` (the clip or the written range of it).
void ExpectRoundTrip(const Clip& clip, std::optional<FrameRange> range = std::nullopt) {
  absl::StatusOr<std::string> text = WriteBvh(clip, range);
  ASSERT_TRUE(text.ok()) << text.status();
  absl::StatusOr<BvhReadResult> back = ReadBvh(*text);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(back->warnings.empty());
  const Clip expected = range ? *clip.Slice(*range) : clip;
  ExpectSameHierarchy(expected.skeleton(), back->clip.skeleton());
  ASSERT_EQ(back->clip.frame_count(), expected.frame_count());
  EXPECT_NEAR(back->clip.frame_time(), expected.frame_time(), 1e-15);
  EXPECT_LT(testing::MaxRotationError(expected, back->clip), kRotationTolerance);
  EXPECT_LT(testing::MaxRelativePositionError(expected, back->clip), kPositionTolerance);
}

TEST(BvhRoundTrip, RandomRotationsInEveryOrder) {
  std::mt19937 rng(21);
  std::normal_distribution<double> n;
  const auto skeleton = testing::ChainSkeleton();  // ZXY, XYZ and YZX joints
  const Clip clip = testing::MakeClip(
      skeleton, 200, 1.0 / 120, [&](int, int) { return Quat(n(rng), n(rng), n(rng), n(rng)); },
      [&](int, int) { return Eigen::Vector3d(n(rng) * 100, n(rng) * 1e-3, n(rng) * 1e4); });
  ExpectRoundTrip(clip);
}

TEST(BvhRoundTrip, GimbalLockedAndFlippingRotations) {
  const auto skeleton = testing::ChainSkeleton();
  const Clip clip = testing::MakeClip(
      skeleton, 64, 1.0 / 30,
      [&](int f, int j) {
        const EulerOrder order = skeleton->rotation_order(j);
        Quat q = EulerToQuaternion(
            Eigen::Vector3d(0.1 * f, (f % 3 - 1) * std::numbers::pi / 2, -0.2 * f), order);
        if (f % 2) q.coeffs() = -q.coeffs();
        return q;
      },
      [](int f, int) { return Eigen::Vector3d(f, 0, -f); });
  ExpectRoundTrip(clip);
}

TEST(BvhRoundTrip, FrameRange) {
  const Clip clip = testing::MakeClip(
      testing::ChainSkeleton(), 50, 1.0 / 30,
      [](int f, int j) {
        return Quat(Eigen::AngleAxisd(0.05 * f * (j + 1), Eigen::Vector3d(1, 1, 0).normalized()));
      },
      [](int f, int) { return Eigen::Vector3d(0, 90 + f, 0); });
  ExpectRoundTrip(clip, FrameRange{10, 20});
  ExpectRoundTrip(clip, FrameRange{49, 49});
  EXPECT_EQ(WriteBvh(clip, FrameRange{40, 50}).status().code(), absl::StatusCode::kOutOfRange);
  EXPECT_EQ(WriteBvh(clip, FrameRange{5, 4}).status().code(), absl::StatusCode::kOutOfRange);
}

// Frames decomposed on several threads and made continuous after (core/bvh/bvh_writer.cc): the
// angles written are the chain of QuaternionToEuler from frame to frame, whatever the thread
// count, across pieces and across the writer's blocks of 4096 frames.
TEST(BvhRoundTrip, ThreadsWriteTheSameContinuousAngles) {
  const auto skeleton = testing::ChainSkeleton();
  constexpr int kFrames = 9000;
  // Winding rotations: the continuous angles reach 90 rad, so a piece or block that started from
  // the wrong previous angles would write them 2 pi (or the other triple) away.
  const Clip clip = testing::MakeClip(
      skeleton, kFrames, 1.0 / 120,
      [&](int f, int j) {
        return EulerToQuaternion(
            Eigen::Vector3d(0.01 * f * (j + 1), 1.2 * std::sin(0.003 * f), -0.007 * f),
            skeleton->rotation_order(j));
      },
      [](int f, int) { return Eigen::Vector3d(f, 0, -f); });
  for (const FrameRange range : {FrameRange{0, kFrames - 1}, FrameRange{1000, 8999}}) {
    const absl::StatusOr<std::string> one = WriteBvh(clip, range, 1);
    ASSERT_TRUE(one.ok()) << one.status();
    for (const int threads : {2, 3, 7}) {
      const absl::StatusOr<std::string> several = WriteBvh(clip, range, threads);
      ASSERT_TRUE(several.ok()) << several.status();
      EXPECT_TRUE(*several == *one) << threads << " threads";
    }
    // The rows' rotation channels against the chain, joint by joint (the chain's joints are
    // written in index order).
    std::istringstream text(one->substr(one->find("Frame Time:")));
    std::string line;
    std::getline(text, line);
    std::vector<Eigen::Vector3d> near(skeleton->joint_count(), Eigen::Vector3d::Zero());
    for (int f = range.first; f <= range.last; ++f) {
      ASSERT_TRUE(std::getline(text, line)) << f;
      std::istringstream row(line);
      for (int j = 0; j < skeleton->joint_count(); ++j) {
        near[j] = QuaternionToEuler(clip.rotation(f, j), skeleton->rotation_order(j), near[j]);
        int rotation = 0;
        for (const Channel c : skeleton->joint(j).channels) {
          double value = 0;
          ASSERT_TRUE(row >> value);
          if (c < Channel::kXrotation) continue;
          ASSERT_NEAR(value, near[j][rotation++] * 180 / std::numbers::pi, 1e-7)
              << "frame " << f << " joint " << j;
        }
      }
      double extra = 0;
      EXPECT_FALSE(row >> extra) << "a value past the last channel in frame " << f;
    }
    EXPECT_FALSE(std::getline(text, line)) << "a row past the last frame: " << line;
  }
}

TEST(BvhRoundTrip, WriteBvhFileIsReadBack) {
  const Clip clip = testing::MakeClip(
      testing::ChainSkeleton(), 5, 0.01, [](int, int) { return Quat::Identity(); },
      [](int f, int) { return Eigen::Vector3d(f, f, f); });
  const std::filesystem::path dir = testing::MakeTempDir("bvh_round_trip_test");
  const std::string path = (dir / "round_trip.bvh").string();
  ASSERT_TRUE(WriteBvhFile(path, clip).ok());
  absl::StatusOr<BvhReadResult> back = ReadBvhFile(path);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->clip.frame_count(), 5);
  EXPECT_FALSE(WriteBvhFile("/nonexistent-dir/x.bvh", clip).ok());
  std::filesystem::remove_all(dir);
}

void ExpectFolderRoundTrips(const std::filesystem::path& dir) {
  for (const std::filesystem::path& path : testing::BvhFilesUnder(dir)) {
    SCOPED_TRACE(path.string());
    absl::StatusOr<BvhReadResult> original = ReadBvhFile(path.string());
    ASSERT_TRUE(original.ok()) << original.status();
    ExpectRoundTrip(original->clip);
  }
}

TEST(BvhRoundTrip, AssimpTestModels) {
  const auto dir = testing::AssimpBvhDir();
  if (!dir) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  ExpectFolderRoundTrips(*dir);
}

TEST(BvhRoundTrip, SharedCorpusExceptBandai) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  for (const char* folder : {"conformance", "cmu", "other-skeletons"}) {
    ExpectFolderRoundTrips(mocap / folder);
  }
}

TEST(BvhRoundTrip, SharedCorpusBandai) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  ExpectFolderRoundTrips(mocap / "bandai1");
  ExpectFolderRoundTrips(mocap / "bandai2-normal");
}

}  // namespace
}  // namespace motiondb
