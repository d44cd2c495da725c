#include "testing/internal/synthetic_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/motion/skeleton.h"

namespace motiondb::testing {
namespace synthetic {
namespace {

// Limb lengths (m) that map a hand-target offset to joint angles: shoulder to wrist, and the
// forearm, matching the skeleton's offsets.
constexpr double kArmLength = 0.53;
constexpr double kForearmLength = 0.25;

// The figure's sides, as the sign of the X coordinate of that side's limbs.
constexpr int kLeft = 1;
constexpr int kRight = -1;

struct JointSpec {
  const char* name;
  int parent;
  Eigen::Vector3d offset;
  std::optional<Eigen::Vector3d> end_site;
};

Skeleton BuildSkeleton() {
  using V = Eigen::Vector3d;
  const std::array<JointSpec, kJointCount> specs = {{
      {"Hips", -1, V(0, 0, 0), std::nullopt},
      {"Spine", kHips, V(0, 10, -1), std::nullopt},
      {"Chest", kSpine, V(0, 18, 0), std::nullopt},
      {"Neck", kChest, V(0, 24, 1), std::nullopt},
      {"Head", kNeck, V(0, 9, 1), V(0, 17, 0)},
      {"LeftCollar", kChest, V(2, 20, 0), std::nullopt},
      {"LeftShoulder", kLeftCollar, V(16, -1, -1), std::nullopt},
      {"LeftElbow", kLeftShoulder, V(0, -28, 0), std::nullopt},
      {"LeftWrist", kLeftElbow, V(0, -25, 0), V(0, -18, 0)},
      {"RightCollar", kChest, V(-2, 20, 0), std::nullopt},
      {"RightShoulder", kRightCollar, V(-16, -1, -1), std::nullopt},
      {"RightElbow", kRightShoulder, V(0, -28, 0), std::nullopt},
      {"RightWrist", kRightElbow, V(0, -25, 0), V(0, -18, 0)},
      {"LeftHip", kHips, V(9, -4, 0), std::nullopt},
      {"LeftKnee", kLeftHip, V(0, -43, 0), std::nullopt},
      {"LeftAnkle", kLeftKnee, V(0, -42, 0), std::nullopt},
      {"LeftToe", kLeftAnkle, V(0, -6, 13), V(0, 0, 5)},
      {"RightHip", kHips, V(-9, -4, 0), std::nullopt},
      {"RightKnee", kRightHip, V(0, -43, 0), std::nullopt},
      {"RightAnkle", kRightKnee, V(0, -42, 0), std::nullopt},
      {"RightToe", kRightAnkle, V(0, -6, 13), V(0, 0, 5)},
  }};
  std::vector<Joint> joints(kJointCount);
  for (int j = 0; j < kJointCount; ++j) {
    joints[j].name = specs[j].name;
    joints[j].parent = specs[j].parent;
    joints[j].offset = specs[j].offset;
    joints[j].end_site = specs[j].end_site;
    joints[j].channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
  }
  joints[kHips].channels.insert(joints[kHips].channels.begin(),
                                {Channel::kXposition, Channel::kYposition, Channel::kZposition});
  absl::StatusOr<Skeleton> skeleton = Skeleton::Create(std::move(joints));
  if (!skeleton.ok()) {
    // The table above is constant, so this is a programming error, not a runtime condition.
    std::fprintf(stderr, "SyntheticSkeleton: %s\n",
                 std::string(skeleton.status().message()).c_str());
    std::abort();
  }
  return *std::move(skeleton);
}

// Raises the arm on `side` forward and up to a hand target displaced by `target` (m) from the
// nominal one: shoulder flexion 150 deg, 12 deg out to the side, elbow bent 25 deg, collar
// lifted 8 deg as the shoulder blade turns up. The cube offset is linearised about the nominal
// raised arm, direction u: its component along the flexion arc p moves the hand by flexion
// (angle = d / arm length), its sideways component by abduction (d / arm length), and its
// component along the arm changes the reach, which the elbow supplies (angle = d / forearm
// length; exact reach geometry is not the point, a bounded, uniform variation of the pose is).
void RaiseArm(int side, const Eigen::Vector3d& target, Pose& pose) {
  const double flexion = 150.0 * kDeg;
  const Eigen::Vector3d u(0.0, -std::cos(flexion), std::sin(flexion));
  const Eigen::Vector3d p(0.0, std::sin(flexion), std::cos(flexion));
  const double flex = flexion + target.dot(p) / kArmLength;
  const double abduction = 12.0 * kDeg + side * target.x() / kArmLength;
  const double elbow = std::max(0.0, 25.0 * kDeg - target.dot(u) / kForearmLength);
  const bool left = side == kLeft;
  // With the arm above the shoulder, -Z tilts the left arm out (+X) and +Z the right one.
  pose[left ? kLeftShoulder : kRightShoulder] = Eigen::Vector3d(-flex, 0.0, -side * abduction);
  pose[left ? kLeftElbow : kRightElbow].x() = -elbow;
  pose[left ? kLeftCollar : kRightCollar].z() += side * 8.0 * kDeg;
}

void Lean(double angle, double spine, double chest, double neck, Pose& pose) {
  pose[kSpine].x() += spine * angle;
  pose[kChest].x() += chest * angle;
  pose[kNeck].x() += neck * angle;
}

}  // namespace

Quat JointRotation(const Eigen::Vector3d& xyz) {
  return EulerToQuaternion(Eigen::Vector3d(xyz.z(), xyz.x(), xyz.y()), EulerOrder::kZXY);
}

// Relaxed standing: arms slightly out from the body with soft elbows, knees slightly bent (the
// thigh, shin and foot angles cancel so the feet stay flat).
Pose RestPose() {
  Pose pose;
  pose.fill(Eigen::Vector3d::Zero());
  for (int side : {kLeft, kRight}) {
    const bool left = side == kLeft;
    pose[left ? kLeftShoulder : kRightShoulder].z() = side * 5.0 * kDeg;
    pose[left ? kLeftElbow : kRightElbow].x() = -10.0 * kDeg;
    pose[left ? kLeftHip : kRightHip].x() = -2.0 * kDeg;
    pose[left ? kLeftKnee : kRightKnee].x() = 4.0 * kDeg;
    pose[left ? kLeftAnkle : kRightAnkle].x() = -2.0 * kDeg;
  }
  return pose;
}

Pose PeakPose(SyntheticAction action, const PoseDraws& draws, const Pose& rest) {
  Pose pose = rest;
  switch (action) {
    case SyntheticAction::kRightArmRaise:
      RaiseArm(kRight, draws.right_target, pose);
      Lean(draws.lean, 0.5, 0.3, 0.2, pose);
      break;
    case SyntheticAction::kLeftArmRaise:
      RaiseArm(kLeft, draws.left_target, pose);
      Lean(draws.lean, 0.5, 0.3, 0.2, pose);
      break;
    case SyntheticAction::kBothArmsRaise:
      RaiseArm(kRight, draws.right_target, pose);
      RaiseArm(kLeft, draws.left_target, pose);
      Lean(draws.lean, 0.5, 0.3, 0.2, pose);
      break;
    case SyntheticAction::kShrug:
      // The thesis's shrugs are identical but for speed: no drawn values. The collars lift 20 deg
      // and the shoulders turn back by as much, so the arms still hang straight down.
      for (int side : {kLeft, kRight}) {
        pose[side == kLeft ? kLeftCollar : kRightCollar].z() += side * 20.0 * kDeg;
        pose[side == kLeft ? kLeftShoulder : kRightShoulder].z() -= side * 20.0 * kDeg;
      }
      break;
    case SyntheticAction::kSlouch:
      // The slouch is itself a posture change: its depth varies instead of a lean. The head
      // lifts back a little to keep looking ahead; the collars roll the shoulders forward.
      Lean(draws.slouch_depth, 0.4, 0.35, 0.25, pose);
      pose[kHead].x() -= 0.3 * draws.slouch_depth;
      pose[kLeftCollar].y() -= kLeft * 0.3 * draws.slouch_depth;
      pose[kRightCollar].y() -= kRight * 0.3 * draws.slouch_depth;
      break;
  }
  return pose;
}

}  // namespace synthetic

std::shared_ptr<const Skeleton> SyntheticSkeleton() {
  static const std::shared_ptr<const Skeleton> skeleton =
      std::make_shared<const Skeleton>(synthetic::BuildSkeleton());
  return skeleton;
}

}  // namespace motiondb::testing
