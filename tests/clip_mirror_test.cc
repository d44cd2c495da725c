#include "core/motion/clip_mirror.h"

#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/match.h"
#include "core/bvh/bvh_reader.h"
#include "core/motion/forward_kinematics.h"
#include "tests/clip_builder.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

// Each joint's world orientation on `frame`.
std::vector<Quat> WorldOrientations(const Clip& clip, int frame) {
  std::vector<Quat> world(clip.skeleton().joint_count());
  for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
    const int parent = clip.skeleton().joint(j).parent;
    world[j] = parent < 0 ? clip.rotation(frame, j) : world[parent] * clip.rotation(frame, j);
  }
  return world;
}

// The largest distance between a joint of `mirrored` and its partner's position in `clip`
// reflected across `mirror.lateral`, over every frame, relative to the clip's reach.
double MirrorPositionError(const Clip& clip, const Clip& mirrored, const SkeletonMirror& mirror) {
  const RowMatrixXd original = ForwardKinematics(clip);
  const RowMatrixXd reflected = ForwardKinematics(mirrored);
  const Eigen::Matrix3d reflection =
      Eigen::Matrix3d::Identity() - 2 * mirror.lateral * mirror.lateral.transpose();
  double worst = 0, reach = 0;
  for (int f = 0; f < clip.frame_count(); ++f) {
    for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
      const Eigen::Vector3d expected =
          reflection * original.block<1, 3>(f, 3 * mirror.partner[j]).transpose();
      worst = std::max(worst, (reflected.block<1, 3>(f, 3 * j).transpose() - expected).norm());
      reach = std::max(reach, expected.norm());
    }
  }
  return worst / reach;
}

// The largest difference (as rotations, sign-exact) between two clips' quaternions.
double MaxQuaternionDifference(const Clip& a, const Clip& b) {
  return (a.rotations() - b.rotations()).cwiseAbs().maxCoeff();
}

struct JointSpec {
  std::string name;
  std::string parent;
  Eigen::Vector3d offset;
};

// A humanoid of 17 joints with symmetric offsets (left is +X, up +Y, facing +Z), every joint
// rotated by 3 channels and the hips also placed by 3. Each joint's rest frame turned by
// `frames[j]` (the identity by default): offsets are then given in the turned parent frame, as
// rigs with baked joint orientations give them (Bandai's), so that the rest pose is no longer
// a standing human.
std::shared_ptr<const Skeleton> Humanoid(const std::vector<Quat>& frames = {}) {
  const std::vector<JointSpec> specs = {
      {"Hips", "", {0, 90, 0}},
      {"Spine", "Hips", {0, 10, 1}},
      {"Chest", "Spine", {0, 20, 0}},
      {"Neck", "Chest", {0, 20, -1}},
      {"Head", "Neck", {0, 10, 0}},
      {"LeftArm", "Chest", {15, 15, 0}},
      {"LeftForeArm", "LeftArm", {25, 0, 0}},
      {"LeftHand", "LeftForeArm", {22, 0, 1}},
      {"RightArm", "Chest", {-15, 15, 0}},
      {"RightForeArm", "RightArm", {-25, 0, 0}},
      {"RightHand", "RightForeArm", {-22, 0, 1}},
      {"LeftUpLeg", "Hips", {9, -5, 0}},
      {"LeftLeg", "LeftUpLeg", {0, -40, 1}},
      {"LeftFoot", "LeftLeg", {0, -40, 0}},
      {"RightUpLeg", "Hips", {-9, -5, 0}},
      {"RightLeg", "RightUpLeg", {0, -40, 1}},
      {"RightFoot", "RightLeg", {0, -40, 0}},
  };
  std::vector<Joint> joints;
  const auto frame = [&](int j) {
    return j < static_cast<int>(frames.size()) ? frames[j] : Quat::Identity();
  };
  for (size_t j = 0; j < specs.size(); ++j) {
    Joint joint;
    joint.name = specs[j].name;
    for (size_t p = 0; p < j; ++p) {
      if (specs[p].name == specs[j].parent) joint.parent = static_cast<int>(p);
    }
    const Quat parent_frame = joint.parent < 0 ? Quat::Identity() : frame(joint.parent);
    joint.offset = parent_frame.conjugate() * specs[j].offset;
    if (j == 0) {
      joint.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
    }
    joint.channels.insert(joint.channels.end(),
                          {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation});
    if (absl::EndsWith(joint.name, "Foot") || joint.name == "Head" ||
        absl::EndsWith(joint.name, "Hand")) {
      joint.end_site = frame(static_cast<int>(j)).conjugate() * Eigen::Vector3d(0, -3, 8);
    }
    joints.push_back(std::move(joint));
  }
  return std::make_shared<const Skeleton>(*Skeleton::Create(std::move(joints)));
}

Quat RandomRotation(std::mt19937& random, double spread) {
  std::normal_distribution<double> normal(0, spread);
  return ExpMap(Eigen::Vector3d(normal(random), normal(random), normal(random)));
}

// A clip of random smooth-enough poses on `skeleton`; `frames` turns each joint's rest frame as
// Humanoid's does, so that the same seed gives the same motion on either skeleton.
Clip RandomClip(std::shared_ptr<const Skeleton> skeleton, const std::vector<Quat>& frames = {}) {
  std::mt19937 random(7);
  const int count = skeleton->joint_count();
  std::vector<std::vector<Quat>> poses(12, std::vector<Quat>(count));
  std::vector<Eigen::Vector3d> roots(12);
  for (int f = 0; f < 12; ++f) {
    for (int j = 0; j < count; ++j) poses[f][j] = RandomRotation(random, 0.6);
    roots[f] = Eigen::Vector3d(f * 3.0, 90 + f, -2.0 * f);
  }
  const auto frame = [&](int j) { return frames.empty() ? Quat::Identity() : frames[j]; };
  std::vector<int> parents;
  for (const Joint& joint : skeleton->joints()) parents.push_back(joint.parent);
  return testing::MakeClip(
      std::move(skeleton), 12, 1.0 / 30,
      [&](int f, int j) {
        const int parent = parents[j];
        const Quat parent_frame = parent < 0 ? Quat::Identity() : frame(parent);
        return parent_frame.conjugate() * poses[f][j] * frame(j);
      },
      [&](int f, int) { return roots[f]; });
}

SkeletonMirror MirrorOf(const Skeleton& skeleton, const RowMatrixXd& reference = {}) {
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(skeleton);
  EXPECT_TRUE(map.ok()) << map.status();
  const absl::StatusOr<SkeletonMirror> mirror = MakeSkeletonMirror(skeleton, *map, reference);
  EXPECT_TRUE(mirror.ok()) << mirror.status();
  return *mirror;
}

TEST(ClipMirror, SyntheticHumanoidMirrorsAcrossItsSagittalPlane) {
  const Clip clip = RandomClip(Humanoid());
  const SkeletonMirror mirror = MirrorOf(clip.skeleton());
  EXPECT_NEAR(std::abs(mirror.lateral.x()), 1, 1e-12);
  EXPECT_LT(mirror.asymmetry, 1e-12);
  const int left_hand = clip.skeleton().FindJoint("LeftHand");
  EXPECT_EQ(mirror.partner[left_hand], clip.skeleton().FindJoint("RightHand"));
  EXPECT_EQ(mirror.partner[clip.skeleton().FindJoint("Head")], clip.skeleton().FindJoint("Head"));
  const absl::StatusOr<Clip> mirrored = MirrorClip(clip, mirror);
  ASSERT_TRUE(mirrored.ok()) << mirrored.status();
  EXPECT_TRUE(mirrored->skeleton().SameTopology(clip.skeleton()));
  EXPECT_LT(MirrorPositionError(clip, *mirrored, mirror), 1e-12);
  // A symmetric rest pose: each rotation is R' = S R_partner S, S = diag(-1, 1, 1).
  const Eigen::Matrix3d s = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  const Eigen::Matrix3d expected = s * clip.rotation(3, left_hand).toRotationMatrix() * s;
  EXPECT_LT(
      (mirrored->rotation(3, clip.skeleton().FindJoint("RightHand")).toRotationMatrix() - expected)
          .norm(),
      1e-12);
  const absl::StatusOr<Clip> twice = MirrorClip(*mirrored, MirrorOf(mirrored->skeleton()));
  ASSERT_TRUE(twice.ok()) << twice.status();
  EXPECT_LT(MaxQuaternionDifference(*twice, clip), 1e-9);
  EXPECT_LT((twice->positions() - clip.positions()).cwiseAbs().maxCoeff(), 1e-9);
  for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
    EXPECT_LT((twice->skeleton().joint(j).offset - clip.skeleton().joint(j).offset).norm(), 1e-9);
  }
}

// A rig whose joints' rest frames are turned (as Bandai's are) mirrors, about a symmetric
// reference pose, into the same motion as the plain rig: the same world positions and the same
// world orientations once each joint's turn is taken out. Its rest pose is refused.
TEST(ClipMirror, TurnedRestFramesMirrorAboutASymmetricReferencePose) {
  std::mt19937 random(3);
  std::vector<Quat> frames;
  for (int j = 0; j < Humanoid()->joint_count(); ++j) frames.push_back(RandomRotation(random, 1.5));
  const std::shared_ptr<const Skeleton> turned = Humanoid(frames);
  const Clip plain = RandomClip(Humanoid());
  const Clip clip = RandomClip(turned, frames);
  // The reference: the pose that undoes each turn, the plain rig's rest pose.
  RowMatrixXd reference(turned->joint_count(), 4);
  for (int j = 0; j < turned->joint_count(); ++j) {
    const int parent = turned->joint(j).parent;
    const Quat q = (parent < 0 ? Quat::Identity() : frames[parent]).conjugate() * frames[j];
    reference.row(j) << q.w(), q.x(), q.y(), q.z();
  }
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(*turned);
  ASSERT_TRUE(map.ok()) << map.status();
  const absl::StatusOr<SkeletonMirror> rest = MakeSkeletonMirror(*turned, *map);
  ASSERT_FALSE(rest.ok());
  EXPECT_EQ(rest.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(rest.status().message()), HasSubstr("rest pose"));

  const SkeletonMirror mirror = MirrorOf(*turned, reference);
  const absl::StatusOr<Clip> mirrored = MirrorClip(clip, mirror);
  ASSERT_TRUE(mirrored.ok()) << mirrored.status();
  EXPECT_LT(MirrorPositionError(clip, *mirrored, mirror), 1e-12);
  const absl::StatusOr<Clip> plain_mirrored = MirrorClip(plain, MirrorOf(plain.skeleton()));
  ASSERT_TRUE(plain_mirrored.ok());
  for (int f = 0; f < clip.frame_count(); ++f) {
    const std::vector<Quat> expected = WorldOrientations(*plain_mirrored, f);
    const std::vector<Quat> got = WorldOrientations(*mirrored, f);
    for (int j = 0; j < turned->joint_count(); ++j) {
      EXPECT_LT(AngleBetween(got[j], expected[j] * frames[j]), 1e-9)
          << "frame " << f << " joint " << j;
    }
  }
  const absl::StatusOr<Clip> twice =
      MirrorClip(*mirrored, MirrorOf(mirrored->skeleton(), reference));
  ASSERT_TRUE(twice.ok());
  EXPECT_LT(MaxQuaternionDifference(*twice, clip), 1e-9);
}

TEST(ClipMirror, RealSkeletonsMirrorExactly) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  for (const std::string file :
       {"cmu/01_01_3dsmax.bvh", "cmu/01_01_motionbuilder.bvh",
        "other-skeletons/cmu1006_walking.bvh", "bandai2-normal/dataset-2_walk_normal_001.bvh"}) {
    SCOPED_TRACE(file);
    const absl::StatusOr<BvhReadResult> read = ReadBvhFile((mocap / file).string());
    ASSERT_TRUE(read.ok()) << read.status();
    const Clip& clip = read->clip;
    const absl::StatusOr<HumanoidMap> map = MapHumanoid(clip.skeleton());
    ASSERT_TRUE(map.ok());
    absl::StatusOr<SkeletonMirror> mirror = MakeSkeletonMirror(clip.skeleton(), *map);
    if (!mirror.ok()) {
      // Bandai's rest pose lays every bone along its parent's x axis: the clip's mean pose is
      // the symmetric reference there.
      EXPECT_THAT(std::string(mirror.status().message()), HasSubstr("rest pose"));
      RowMatrixXd mean(clip.skeleton().joint_count(), 4);
      for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
        const absl::StatusOr<Quat> q = MeanQuaternion(clip.rotations().middleCols(4 * j, 4));
        ASSERT_TRUE(q.ok());
        mean.row(j) << q->w(), q->x(), q->y(), q->z();
      }
      mirror = MakeSkeletonMirror(clip.skeleton(), *map, mean);
      ASSERT_TRUE(mirror.ok()) << mirror.status();
    }
    const absl::StatusOr<Clip> mirrored = MirrorClip(clip, *mirror);
    ASSERT_TRUE(mirrored.ok()) << mirrored.status();
    EXPECT_LT(MirrorPositionError(clip, *mirrored, *mirror), 1e-9);
    const absl::StatusOr<Clip> twice = MirrorClip(*mirrored, *mirror);
    ASSERT_TRUE(twice.ok());
    EXPECT_LT(MaxQuaternionDifference(*twice, clip), 1e-9);
    EXPECT_LT((twice->positions() - clip.positions()).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(ClipMirror, AnUnmappableSkeletonIsRefusedNamingItsMissingSlots) {
  // The humanoid without its arms.
  const std::shared_ptr<const Skeleton> whole = Humanoid();
  std::vector<Joint> joints;
  for (const Joint& joint : whole->joints()) {
    if (absl::StrContains(joint.name, "Arm") || absl::StrContains(joint.name, "Hand")) continue;
    joints.push_back(joint);
  }
  std::vector<Joint> renumbered = joints;
  for (Joint& joint : renumbered) {
    if (joint.parent < 0) continue;
    const std::string& parent = whole->joint(joint.parent).name;
    for (size_t p = 0; p < joints.size(); ++p) {
      if (joints[p].name == parent) joint.parent = static_cast<int>(p);
    }
  }
  const absl::StatusOr<Skeleton> armless = Skeleton::Create(std::move(renumbered));
  ASSERT_TRUE(armless.ok()) << armless.status();
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(*armless);
  ASSERT_TRUE(map.ok());
  const absl::StatusOr<SkeletonMirror> mirror = MakeSkeletonMirror(*armless, *map);
  ASSERT_FALSE(mirror.ok());
  EXPECT_EQ(mirror.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(mirror.status().message()), HasSubstr("LeftUpperArm"));
  EXPECT_THAT(std::string(mirror.status().message()), HasSubstr("RightHand"));
}

TEST(ClipMirror, AMirrorOfAnotherSkeletonOrAReferenceOfTheWrongShapeIsRefused) {
  const Clip clip = RandomClip(Humanoid());
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(clip.skeleton());
  ASSERT_TRUE(map.ok());
  EXPECT_EQ(MakeSkeletonMirror(clip.skeleton(), *map, RowMatrixXd::Zero(3, 4)).status().code(),
            absl::StatusCode::kInvalidArgument);
  SkeletonMirror mirror = MirrorOf(clip.skeleton());
  mirror.partner.pop_back();
  EXPECT_EQ(MirrorClip(clip, mirror).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace motiondb
