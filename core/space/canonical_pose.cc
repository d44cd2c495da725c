#include "core/space/canonical_pose.h"

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/motion/forward_kinematics.h"
#include "core/space/heading.h"
#include "core/space/root_velocity.h"

namespace motiondb {
namespace {

using Slot = HumanoidSlot;

// A bone's two ends: a slot each, or the midpoint of a left/right pair of slots (`*_pair`). A bone
// is named by its slot, as HumanIK and VRM name theirs (the thigh is "LeftUpperLeg"; the trunk,
// hips to shoulders, "Spine"); the shoulder line, two slots' bone, "Shoulders".
struct BoneEnds {
  absl::string_view name;
  Slot from;
  Slot from_pair;  // == from when the end is one joint
  Slot to;
  Slot to_pair;
};

constexpr std::array<BoneEnds, kCanonicalBoneCount> kBones = {{
    {"LeftUpperLeg", Slot::kLeftUpperLeg, Slot::kLeftUpperLeg, Slot::kLeftLowerLeg,
     Slot::kLeftLowerLeg},
    {"LeftLowerLeg", Slot::kLeftLowerLeg, Slot::kLeftLowerLeg, Slot::kLeftFoot, Slot::kLeftFoot},
    {"RightUpperLeg", Slot::kRightUpperLeg, Slot::kRightUpperLeg, Slot::kRightLowerLeg,
     Slot::kRightLowerLeg},
    {"RightLowerLeg", Slot::kRightLowerLeg, Slot::kRightLowerLeg, Slot::kRightFoot,
     Slot::kRightFoot},
    {"LeftUpperArm", Slot::kLeftUpperArm, Slot::kLeftUpperArm, Slot::kLeftLowerArm,
     Slot::kLeftLowerArm},
    {"LeftLowerArm", Slot::kLeftLowerArm, Slot::kLeftLowerArm, Slot::kLeftHand, Slot::kLeftHand},
    {"RightUpperArm", Slot::kRightUpperArm, Slot::kRightUpperArm, Slot::kRightLowerArm,
     Slot::kRightLowerArm},
    {"RightLowerArm", Slot::kRightLowerArm, Slot::kRightLowerArm, Slot::kRightHand,
     Slot::kRightHand},
    {"Spine", Slot::kLeftUpperLeg, Slot::kRightUpperLeg, Slot::kLeftUpperArm, Slot::kRightUpperArm},
    {"Neck", Slot::kLeftUpperArm, Slot::kRightUpperArm, Slot::kHead, Slot::kHead},
    {"Shoulders", Slot::kRightUpperArm, Slot::kRightUpperArm, Slot::kLeftUpperArm,
     Slot::kLeftUpperArm},
}};

// Each bone's mirror partner in kBones, and whether the partner runs the other way (the
// shoulder line, from right to left, mirrors into itself from left to right).
constexpr std::array<int, kCanonicalBoneCount> kMirrorBone = {2, 3, 0, 1, 6, 7, 4, 5, 8, 9, 10};
constexpr int kReversedByMirror = 10;

// The slots the bones read, in enum order.
constexpr std::array<Slot, 13> kUsedSlots = {
    Slot::kHead,          Slot::kLeftUpperArm,  Slot::kLeftLowerArm,  Slot::kLeftHand,
    Slot::kRightUpperArm, Slot::kRightLowerArm, Slot::kRightHand,     Slot::kLeftUpperLeg,
    Slot::kLeftLowerLeg,  Slot::kLeftFoot,      Slot::kRightUpperLeg, Slot::kRightLowerLeg,
    Slot::kRightFoot,
};

// Below this a direction is taken as undefined (two joints at one place, a vertical hip line).
constexpr double kTinyLength = 1e-9;

// Every joint's world position on every frame, read by slot.
class SlotPositions {
 public:
  SlotPositions(const Clip& clip, const HumanoidMap& map)
      : positions_(ForwardKinematics(clip)), map_(map) {}

  Eigen::Vector3d At(int frame, Slot slot) const {
    const int j = map_.joint(slot);
    return positions_.block<1, 3>(frame, 3 * j).transpose();
  }
  Eigen::Vector3d Mid(int frame, Slot a, Slot b) const {
    return a == b ? At(frame, a) : 0.5 * (At(frame, a) + At(frame, b));
  }

 private:
  RowMatrixXd positions_;
  const HumanoidMap& map_;
};

// The signed world axis nearest the clip's mean trunk direction.
Eigen::Vector3d UpAxis(const SlotPositions& at, int frames) {
  Eigen::Vector3d trunk = Eigen::Vector3d::Zero();
  for (int f = 0; f < frames; ++f) {
    const Eigen::Vector3d d = at.Mid(f, Slot::kLeftUpperArm, Slot::kRightUpperArm) -
                              at.Mid(f, Slot::kLeftUpperLeg, Slot::kRightUpperLeg);
    const double norm = d.norm();
    if (norm > kTinyLength) trunk += d / norm;
  }
  Eigen::Index axis = 1;  // Y, motiondb's up, when the trunk tells nothing
  if (trunk.norm() > kTinyLength) trunk.cwiseAbs().maxCoeff(&axis);
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  up[axis] = trunk[axis] < 0.0 ? -1.0 : 1.0;
  return up;
}

// The mean length of the two legs (thigh plus shin) over the frames, in the clip's units; 1 when
// the legs have no length.
double MeanLegLength(const SlotPositions& at, int frames) {
  double sum = 0.0;
  for (int f = 0; f < frames; ++f) {
    for (const auto& [hip, knee, ankle] :
         {std::array{Slot::kLeftUpperLeg, Slot::kLeftLowerLeg, Slot::kLeftFoot},
          std::array{Slot::kRightUpperLeg, Slot::kRightLowerLeg, Slot::kRightFoot}}) {
      sum += 0.5 *
             ((at.At(f, knee) - at.At(f, hip)).norm() + (at.At(f, ankle) - at.At(f, knee)).norm());
    }
  }
  const double mean = frames > 0 ? sum / frames : 0.0;
  return mean > kTinyLength ? mean : 1.0;
}

// `v` without its component along `up`, made unit; zero when nothing is left.
Eigen::Vector3d Horizontal(const Eigen::Vector3d& v, const Eigen::Vector3d& up) {
  const Eigen::Vector3d h = v - v.dot(up) * up;
  const double norm = h.norm();
  return norm > kTinyLength ? Eigen::Vector3d(h / norm) : Eigen::Vector3d::Zero();
}

}  // namespace

absl::string_view SpaceRepresentationName(SpaceRepresentation representation) {
  return representation == SpaceRepresentation::kCanonicalBones ? "canonical-bones"
                                                                : "joint-rotations";
}

absl::StatusOr<SpaceRepresentation> ParseSpaceRepresentation(absl::string_view name) {
  for (const SpaceRepresentation r :
       {SpaceRepresentation::kJointRotations, SpaceRepresentation::kCanonicalBones}) {
    if (name == SpaceRepresentationName(r)) return r;
  }
  return absl::InvalidArgumentError(absl::StrCat("unknown space representation '", name,
                                                 "': expected joint-rotations or canonical-bones"));
}

absl::string_view CanonicalBoneName(int bone) { return kBones[bone].name; }

absl::Status CheckCanonicalMap(const HumanoidMap& map, absl::string_view skeleton_name) {
  std::vector<std::string> missing;
  for (const Slot slot : kUsedSlots) {
    if (map.joint(slot) < 0) missing.emplace_back(HumanoidSlotName(slot));
  }
  if (missing.empty()) return absl::OkStatus();
  return absl::FailedPreconditionError(absl::StrCat(
      "skeleton ", skeleton_name, " cannot join a space over several skeletons: its humanoid map ",
      "has no joint for ", absl::StrJoin(missing, ", "),
      " (set them with `motiondb skeletons map`)"));
}

int CanonicalPoseDims(const PoseOptions& options) {
  return 3 * kCanonicalBoneCount + 1 + (options.root_velocity ? kRootVelocityDims : 0);
}

RowMatrixXd CanonicalPoses(const Clip& clip, const HumanoidMap& map, const PoseOptions& options) {
  const int frames = clip.frame_count();
  const SlotPositions at(clip, map);
  const Eigen::Vector3d up = UpAxis(at, frames);
  const double leg = MeanLegLength(at, frames);

  RowMatrixXd poses(frames, CanonicalPoseDims(options));
  // The heading frame of each frame (left, forward), the yaw unwrapped frame to frame, and the
  // point between the hips.
  std::vector<Eigen::Vector3d> lefts(frames), forwards(frames);
  Eigen::VectorXd yaw(frames);
  RowMatrixXd between_hips(frames, 3);
  Eigen::Vector3d left_before = Eigen::Vector3d::Zero();
  for (int f = 0; f < frames; ++f) {
    Eigen::Vector3d left =
        Horizontal(at.At(f, Slot::kLeftUpperLeg) - at.At(f, Slot::kRightUpperLeg), up);
    if (left.isZero()) {
      left = Horizontal(at.At(f, Slot::kLeftUpperArm) - at.At(f, Slot::kRightUpperArm), up);
    }
    if (left.isZero()) {  // any horizontal axis, then the last frame's
      left = left_before.isZero() ? Eigen::Vector3d(up.z(), up.x(), up.y()) : left_before;
    }
    const Eigen::Vector3d forward = left.cross(up);
    // The turn about up from the frame before, in (-pi, pi].
    yaw[f] = f == 0
                 ? 0.0
                 : yaw[f - 1] + std::atan2(up.dot(left_before.cross(left)), left_before.dot(left));
    lefts[f] = left;
    forwards[f] = forward;
    left_before = left;
    between_hips.row(f) = at.Mid(f, Slot::kLeftUpperLeg, Slot::kRightUpperLeg).transpose();
    for (int b = 0; b < kCanonicalBoneCount; ++b) {
      const BoneEnds& bone = kBones[b];
      Eigen::Vector3d d = at.Mid(f, bone.to, bone.to_pair) - at.Mid(f, bone.from, bone.from_pair);
      const double norm = d.norm();
      d = norm > kTinyLength ? Eigen::Vector3d(d / norm) : Eigen::Vector3d::Zero();
      poses.block<1, 3>(f, 3 * b) << d.dot(left), d.dot(up), d.dot(forward);
    }
  }
  const double fps = clip.fps();
  poses.col(3 * kCanonicalBoneCount) = YawRate(yaw, fps, options.yaw_rate_window);
  if (options.root_velocity) {
    std::array<Eigen::VectorXd, 3> velocity;
    for (int axis = 0; axis < 3; ++axis) {
      velocity[axis] = YawRate(between_hips.col(axis), fps, options.yaw_rate_window) / leg;
    }
    for (int f = 0; f < frames; ++f) {
      const Eigen::Vector3d v(velocity[0][f], velocity[1][f], velocity[2][f]);
      poses(f, 3 * kCanonicalBoneCount + 1) = v.dot(lefts[f]);
      poses(f, 3 * kCanonicalBoneCount + 2) = v.dot(forwards[f]);
    }
  }
  return poses;
}

absl::Status MirrorCanonicalPoses(const PoseOptions& options, RowMatrixXd* poses) {
  if (poses->cols() != CanonicalPoseDims(options)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "canonical poses have ", poses->cols(), " numbers; expected ", CanonicalPoseDims(options)));
  }
  const RowMatrixXd source = *poses;
  for (int b = 0; b < kCanonicalBoneCount; ++b) {
    // (left, up, forward) of the partner, the mirror's left negated.
    const auto partner = source.middleCols<3>(3 * kMirrorBone[b]);
    auto bone = poses->middleCols<3>(3 * b);
    bone.col(0) = -partner.col(0);
    bone.rightCols<2>() = partner.rightCols<2>();
    if (b == kReversedByMirror) bone = -bone;
  }
  const int yaw_rate = 3 * kCanonicalBoneCount;
  poses->col(yaw_rate) = -source.col(yaw_rate);
  if (options.root_velocity) poses->col(yaw_rate + 1) = -source.col(yaw_rate + 1);  // leftward
  return absl::OkStatus();
}

}  // namespace motiondb
