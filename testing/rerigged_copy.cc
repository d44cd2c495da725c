#include "testing/rerigged_copy.h"

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "util/status_macros.h"

namespace motiondb::testing {
namespace {

// The copy's name of each Bandai joint it keeps; the rest (joint_Root, the toes) are dropped.
const std::map<std::string, std::string>& NewNames() {
  static const auto* names = new std::map<std::string, std::string>{
      {"Hips", "Hips"},
      {"Spine", "Spine"},
      {"Chest", "Spine1"},
      {"Neck", "Neck"},
      {"Head", "Head"},
      {"Shoulder_L", "LeftShoulder"},
      {"UpperArm_L", "LeftArm"},
      {"LowerArm_L", "LeftForeArm"},
      {"Hand_L", "LeftHand"},
      {"Shoulder_R", "RightShoulder"},
      {"UpperArm_R", "RightArm"},
      {"LowerArm_R", "RightForeArm"},
      {"Hand_R", "RightHand"},
      {"UpperLeg_L", "LeftUpLeg"},
      {"LowerLeg_L", "LeftLeg"},
      {"Foot_L", "LeftFoot"},
      {"UpperLeg_R", "RightUpLeg"},
      {"LowerLeg_R", "RightLeg"},
      {"Foot_R", "RightFoot"},
  };
  return *names;
}

constexpr absl::string_view kPrefix = "mixamorig:";
constexpr absl::string_view kInsertedAfter = "Chest";  // the extra joint goes below it
constexpr absl::string_view kMovedBelow = "Neck";      // and the neck below the extra joint

struct NewJoint {
  int source = -1;  // the original joint, or -1 for the inserted one
  Quat rest_turn;   // C: the copy's world rotation is RerigUpTurn() * original's * C
};

// The original's local translation of joint j on frame f: its position channels or its offset.
Eigen::Vector3d Translation(const Clip& clip, int j, int f) {
  const int slot = clip.skeleton().position_slot(j);
  return slot < 0 ? clip.skeleton().joint(j).offset
                  : Eigen::Vector3d(clip.positions().block<1, 3>(f, 3 * slot).transpose());
}

Quat LocalRotation(const Clip& clip, int j, int f) {
  const auto row = clip.rotations().row(f);
  return Quat(row[4 * j], row[4 * j + 1], row[4 * j + 2], row[4 * j + 3]);
}

}  // namespace

Quat RerigUpTurn() {
  return Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX()));
}

absl::StatusOr<Clip> ReriggedCopy(const Clip& clip) {
  const Skeleton& source = clip.skeleton();
  const int hips = source.FindJoint("Hips");
  if (hips < 0 || source.FindJoint(std::string(kInsertedAfter)) < 0) {
    return absl::InvalidArgumentError("ReriggedCopy needs a Bandai skeleton (Hips, Chest, ...)");
  }
  // The copy's joints in the original's order (parents before children), the extra one right
  // after the chest.
  std::vector<Joint> joints;
  std::vector<NewJoint> plan;
  std::vector<int> new_index(source.joint_count(), -1);
  int inserted = -1;
  for (int j = 0; j < source.joint_count(); ++j) {
    const Joint& original = source.joint(j);
    const auto name = NewNames().find(original.name);
    if (name == NewNames().end()) continue;
    Joint joint;
    joint.name = absl::StrCat(kPrefix, name->second);
    const int parent = original.parent < 0 ? -1 : new_index[original.parent];
    joint.parent = original.name == kMovedBelow ? inserted : parent;
    const bool upper_arm = original.name.rfind("UpperArm", 0) == 0;
    const Eigen::Vector3d axis = Eigen::Vector3d(1.0, j % 3, 2.0).normalized();
    const Quat turn = upper_arm
                          ? Quat(Eigen::AngleAxisd(std::numbers::pi / 4, Eigen::Vector3d::UnitZ()))
                          : Quat(Eigen::AngleAxisd(0.3 + 0.1 * j, axis));
    joint.channels = {Channel::kXrotation, Channel::kYrotation, Channel::kZrotation};
    if (j == hips) {
      joint.channels.insert(joint.channels.begin(),
                            {Channel::kXposition, Channel::kYposition, Channel::kZposition});
    }
    new_index[j] = static_cast<int>(plan.size());
    plan.push_back({j, turn});
    joints.push_back(std::move(joint));
    if (original.name == kInsertedAfter) {
      inserted = static_cast<int>(plan.size());
      plan.push_back({-1, turn});  // turns with the chest: its local rotation is the identity
      joints.push_back({absl::StrCat(kPrefix, "Spine2"),
                        new_index[j],
                        Eigen::Vector3d::Zero(),
                        {Channel::kXrotation, Channel::kYrotation, Channel::kZrotation},
                        std::nullopt});
    }
  }
  // Offsets from frame 0's translations, each turned into its parent's new rest frame and
  // scaled; the extra joint takes half of the neck's. End Sites likewise, the feet's at the toes.
  for (int j = 0; j < source.joint_count(); ++j) {
    const int k = new_index[j];
    const Joint& original = source.joint(j);
    if (k < 0) {  // a dropped toe: its parent foot ends where it began
      const int foot = original.parent >= 0 ? new_index[original.parent] : -1;
      if (foot >= 0) {
        joints[foot].end_site =
            kRerigScale * (plan[foot].rest_turn.conjugate() * Translation(clip, j, 0));
      }
      continue;
    }
    if (original.end_site) {
      joints[k].end_site = kRerigScale * (plan[k].rest_turn.conjugate() * *original.end_site);
    }
    const int parent = joints[k].parent;
    if (parent < 0) continue;
    const Eigen::Vector3d offset =
        kRerigScale * (plan[parent].rest_turn.conjugate() * Translation(clip, j, 0));
    if (parent == inserted) {
      joints[parent].offset = 0.5 * offset;
      joints[k].offset = 0.5 * offset;
    } else {
      joints[k].offset = offset;
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(Skeleton skeleton, Skeleton::Create(joints));
  auto shared = std::make_shared<const Skeleton>(std::move(skeleton));

  // Each frame: the original's world rotations and the hips' world position, then the copy's
  // local rotations W'_parent^-1 W'_k with W'_k = up * W_k * C_k.
  const int frames = clip.frame_count();
  const int count = static_cast<int>(plan.size());
  RowMatrixXd rotations(frames, 4 * count);
  RowMatrixXd positions(frames, 3);
  const Quat up = RerigUpTurn();
  std::vector<Quat> world(source.joint_count());
  std::vector<Eigen::Vector3d> place(source.joint_count());
  std::vector<Quat> new_world(count);
  for (int f = 0; f < frames; ++f) {
    for (int j = 0; j < source.joint_count(); ++j) {
      const int parent = source.joint(j).parent;
      const Quat parent_world = parent < 0 ? Quat::Identity() : world[parent];
      place[j] = (parent < 0 ? Eigen::Vector3d::Zero() : place[parent]) +
                 parent_world * Translation(clip, j, f);
      world[j] = parent_world * LocalRotation(clip, j, f);
    }
    positions.row(f) = (kRerigScale * (up * place[hips])).transpose();
    for (int k = 0; k < count; ++k) {
      new_world[k] =
          plan[k].source >= 0 ? up * world[plan[k].source] * plan[k].rest_turn : new_world[k - 1];
      const int parent = joints[k].parent;
      const Quat local =
          (parent < 0 ? new_world[k] : new_world[parent].conjugate() * new_world[k]).normalized();
      rotations.block<1, 4>(f, 4 * k) << local.w(), local.x(), local.y(), local.z();
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const Clip copy,
      Clip::Create(shared, clip.frame_time(), std::move(rotations), std::move(positions)));
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, WriteBvh(copy));
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvh(text));
  return std::move(read.clip);
}

}  // namespace motiondb::testing
