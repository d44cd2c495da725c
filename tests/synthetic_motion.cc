#include "tests/synthetic_motion.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "absl/strings/match.h"
#include "tests/clip_builder.h"

namespace motiondb::testing {
namespace {

constexpr double kPi = std::numbers::pi;

Quat AxisAngle(double angle, const Eigen::Vector3d& axis) {
  return Quat(Eigen::AngleAxisd(angle, axis.normalized()));
}

void AddJoint(std::vector<Joint>& joints, const std::string& name, const std::string& parent,
              const Eigen::Vector3d& offset, bool positions = false) {
  Joint joint;
  joint.name = name;
  for (int j = 0; j < static_cast<int>(joints.size()); ++j) {
    if (joints[j].name == parent) joint.parent = j;
  }
  joint.offset = offset;
  if (positions) {
    joint.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
  }
  joint.channels.insert(joint.channels.end(),
                        {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation});
  joints.push_back(std::move(joint));
}

}  // namespace

std::shared_ptr<const Skeleton> HumanoidSkeleton(bool still_root) {
  std::vector<Joint> joints;
  if (still_root) AddJoint(joints, "Root", "", Eigen::Vector3d::Zero(), true);
  AddJoint(joints, "Hips", "Root", Eigen::Vector3d(0, 90, 0), true);
  AddJoint(joints, "Spine", "Hips", Eigen::Vector3d(0, 10, 0));
  AddJoint(joints, "Chest", "Spine", Eigen::Vector3d(0, 15, 0));
  AddJoint(joints, "Neck", "Chest", Eigen::Vector3d(0, 20, 0));
  AddJoint(joints, "Head", "Neck", Eigen::Vector3d(0, 8, 0));
  for (const double side : {1.0, -1.0}) {
    const std::string s = side > 0 ? "_L" : "_R";
    AddJoint(joints, "Shoulder" + s, "Chest", Eigen::Vector3d(5 * side, 18, 0));
    AddJoint(joints, "UpperArm" + s, "Shoulder" + s, Eigen::Vector3d(10 * side, 0, 0));
    AddJoint(joints, "LowerArm" + s, "UpperArm" + s, Eigen::Vector3d(28 * side, 0, 0));
    AddJoint(joints, "Hand" + s, "LowerArm" + s, Eigen::Vector3d(25 * side, 0, 0));
    AddJoint(joints, "UpperLeg" + s, "Hips", Eigen::Vector3d(9 * side, 0, 0));
    AddJoint(joints, "LowerLeg" + s, "UpperLeg" + s, Eigen::Vector3d(0, -42, 0));
    AddJoint(joints, "Foot" + s, "LowerLeg" + s, Eigen::Vector3d(0, -40, 5));
  }
  for (Joint& joint : joints) {
    if (joint.name == "Head" || absl::StartsWith(joint.name, "Hand") ||
        absl::StartsWith(joint.name, "Foot")) {
      joint.end_site = Eigen::Vector3d::Zero();
    }
  }
  absl::StatusOr<Skeleton> skeleton = Skeleton::Create(std::move(joints));
  EXPECT_TRUE(skeleton.ok()) << skeleton.status();
  return std::make_shared<const Skeleton>(*std::move(skeleton));
}

std::vector<int> LegJoints(const Skeleton& skeleton) {
  std::vector<int> legs;
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const std::string& name = skeleton.joint(j).name;
    if (absl::StrContains(name, "Leg") || absl::StrContains(name, "Foot")) legs.push_back(j);
  }
  return legs;
}

Clip SyntheticClip(std::shared_ptr<const Skeleton> skeleton, const SyntheticMotion& motion) {
  const Skeleton& body = *skeleton;
  const int pelvis = body.FindJoint("Hips");
  const auto rotation = [&](int f, int j) -> Quat {
    const double t = f / motion.fps;
    if (j < pelvis) return AxisAngle(0.4, Eigen::Vector3d::UnitY());  // still, facing aside
    // Incommensurate frequencies (0.4-2.4 Hz) and phases per joint, axis and seed.
    const auto wave = [&](int axis) {
      const double k = 3 * j + axis + 0.61 * motion.seed;
      const double hz = 0.4 + std::fmod(0.7548776662 * k, 2.0);
      return std::sin(2 * kPi * hz * t + 1.3 * k);
    };
    if (j == pelvis) {
      // The facing turns; the pelvis tilts a little; Bandai-like rest frame (X up).
      return AxisAngle(motion.turn_rate * t + 0.2 * wave(1), Eigen::Vector3d::UnitY()) *
             AxisAngle(0.1 * wave(0), Eigen::Vector3d::UnitX()) *
             AxisAngle(kPi / 2, Eigen::Vector3d::UnitZ());
    }
    const std::string& name = body.joint(j).name;
    double amplitude = motion.body_amplitude;
    if (absl::StrContains(name, "Arm") || absl::StrContains(name, "Hand") ||
        absl::StrContains(name, "Shoulder")) {
      amplitude = motion.arm_amplitude;
    } else if (absl::StrContains(name, "Leg") || absl::StrContains(name, "Foot")) {
      amplitude = motion.leg_amplitude;
    }
    return AxisAngle(amplitude * wave(0), Eigen::Vector3d::UnitX()) *
           AxisAngle(0.5 * amplitude * wave(1), Eigen::Vector3d::UnitY()) *
           AxisAngle(0.7 * amplitude * wave(2), Eigen::Vector3d::UnitZ());
  };
  const auto position = [&](int f, int j) -> Eigen::Vector3d {
    if (j < pelvis) return Eigen::Vector3d::Zero();
    return Eigen::Vector3d(0.5 * f, 90 + std::sin(0.1 * f), 0.2 * f);
  };
  return MakeClip(std::move(skeleton), motion.frames, 1.0 / motion.fps, rotation, position);
}

Clip TurnedClip(const Clip& clip, double angle) {
  const Skeleton& skeleton = clip.skeleton();
  const int pelvis = skeleton.FindJoint("Hips");
  const Quat turn = AxisAngle(angle, Eigen::Vector3d::UnitY());
  RowMatrixXd rotations = clip.rotations();
  RowMatrixXd positions = clip.positions();
  std::vector<int> chain;  // the pelvis first, the root last
  for (int j = pelvis; j >= 0; j = skeleton.joint(j).parent) chain.push_back(j);
  for (int f = 0; f < clip.frame_count(); ++f) {
    // Each translation of the chain turns in its parent's frame, so the world positions turn.
    Quat above = Quat::Identity();  // the global orientation of the chain joint's parent
    for (auto j = chain.rbegin(); j != chain.rend(); ++j) {
      const int slot = skeleton.position_slot(*j);
      if (slot >= 0) {
        const Eigen::Vector3d local = positions.block<1, 3>(f, 3 * slot).transpose();
        positions.block<1, 3>(f, 3 * slot) = (above.conjugate() * turn * above * local).transpose();
      }
      if (*j != pelvis) above = above * clip.rotation(f, *j);
    }
    const Quat local = above.conjugate() * turn * above * clip.rotation(f, pelvis);
    rotations.block<1, 4>(f, 4 * pelvis) << local.w(), local.x(), local.y(), local.z();
  }
  absl::StatusOr<Clip> turned =
      Clip::Create(clip.shared_skeleton(), clip.frame_time(), rotations, positions);
  EXPECT_TRUE(turned.ok()) << turned.status();
  return *std::move(turned);
}

}  // namespace motiondb::testing
