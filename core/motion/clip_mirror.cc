#include "core/motion/clip_mirror.h"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// Each joint's partner (itself when it has none); FAILED_PRECONDITION unless partners' parents
// are partners, so that the mirrored hierarchy is the skeleton's own.
absl::StatusOr<std::vector<int>> Partners(const Skeleton& skeleton, const HumanoidMap& map) {
  std::vector<int> partner(skeleton.joint_count());
  for (int j = 0; j < skeleton.joint_count(); ++j) partner[j] = j;
  for (const auto& [left, right] : map.mirror_pairs) {
    partner[left] = right;
    partner[right] = left;
  }
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const int parent = skeleton.joint(j).parent;
    const int partner_parent = skeleton.joint(partner[j]).parent;
    if (partner_parent == (parent < 0 ? -1 : partner[parent])) continue;
    const std::string name = skeleton.joint(j).name.substr(0, 128);
    if (partner[j] == j) {
      return absl::FailedPreconditionError(absl::StrCat(
          "joint '", name, "' has no mirror partner but its parent '",
          skeleton.joint(parent).name.substr(0, 128), "' has one ('",
          skeleton.joint(partner[parent]).name.substr(0, 128),
          "'): the map pairs a side's joints by their names and by the hierarchy; map the "
          "skeleton's slots so that each side's chains match"));
    }
    return absl::FailedPreconditionError(
        absl::StrCat("joints '", name, "' and '", skeleton.joint(partner[j]).name.substr(0, 128),
                     "' are mirror partners but their parents are not"));
  }
  return partner;
}

// The world reflection's axis: from the right joints to the left ones, square to `up`.
Eigen::Vector3d LateralAxis(const std::vector<std::pair<int, int>>& pairs,
                            const std::vector<Eigen::Vector3d>& position,
                            const Eigen::Vector3d& up) {
  Eigen::Vector3d across = Eigen::Vector3d::Zero();
  for (const auto& [left, right] : pairs) across += position[left] - position[right];
  return across - across.dot(up) * up;
}

Eigen::Vector3d Reflect(const Eigen::Vector3d& axis, const Eigen::Vector3d& v) {
  return v - 2 * axis.dot(v) * axis;
}

// S^T t for the reflection S held as the rotation -S's quaternion.
Eigen::Vector3d ReflectBack(const Quat& reflection, const Eigen::Vector3d& t) {
  return -(reflection.conjugate() * t);
}

}  // namespace

absl::StatusOr<SkeletonMirror> MakeSkeletonMirror(const Skeleton& skeleton, const HumanoidMap& map,
                                                  const RowMatrixXd& reference) {
  const int count = skeleton.joint_count();
  if (!map.complete()) {
    std::vector<std::string> missing;
    for (const HumanoidSlot slot : map.missing) missing.emplace_back(HumanoidSlotName(slot));
    return absl::FailedPreconditionError(absl::StrCat(
        "the skeleton's humanoid map lacks the slots ", absl::StrJoin(missing, ", "),
        ": without them its sides cannot be told apart (map them: skeletons map ID --slot "
        "SLOT=JOINT)"));
  }
  if (reference.size() > 0 && (reference.rows() != count || reference.cols() != 4)) {
    return absl::InvalidArgumentError(absl::StrCat("reference: ", reference.rows(), " x ",
                                                   reference.cols(), " numbers for a skeleton of ",
                                                   count, " joints (joints x 4 wanted)"));
  }
  SkeletonMirror mirror;
  MOTIONDB_ASSIGN_OR_RETURN(mirror.partner, Partners(skeleton, map));

  // The reference pose in the world: each joint's orientation and position.
  std::vector<Quat> orientation(count, Quat::Identity());
  std::vector<Eigen::Vector3d> position(count, Eigen::Vector3d::Zero());
  for (int j = 0; j < count; ++j) {
    const Quat local =
        reference.size() > 0
            ? Quat(reference(j, 0), reference(j, 1), reference(j, 2), reference(j, 3)).normalized()
            : Quat::Identity();
    const int parent = skeleton.joint(j).parent;
    orientation[j] = parent < 0 ? local : orientation[parent] * local;
    position[j] =
        parent < 0
            ? skeleton.joint(j).offset
            : Eigen::Vector3d(position[parent] + orientation[parent] * skeleton.joint(j).offset);
  }
  const Eigen::Vector3d hips = position[map.joint(HumanoidSlot::kHips)];
  double reach = 0;
  for (const Eigen::Vector3d& at : position) reach = std::max(reach, (at - hips).norm());
  const Eigen::Vector3d up = (position[map.joint(HumanoidSlot::kHead)] - hips).normalized();
  const Eigen::Vector3d across = LateralAxis(map.mirror_pairs, position, up);
  const std::string pose = reference.size() > 0 ? "the reference pose" : "the rest pose";
  if (!(reach > 0) || !(across.norm() > 1e-6 * reach) || !up.allFinite()) {
    return absl::FailedPreconditionError(absl::StrCat(
        pose, " shows no left and right: its paired joints do not lie apart across the body"));
  }
  mirror.lateral = across.normalized();

  // How far each joint lies from its partner's mirror image, across the plane through the hips.
  int worst = 0;
  for (int j = 0; j < count; ++j) {
    const double off =
        ((position[j] - hips) - Reflect(mirror.lateral, position[mirror.partner[j]] - hips)).norm();
    if (off > mirror.asymmetry) mirror.asymmetry = off, worst = j;
  }
  mirror.asymmetry /= reach;
  if (mirror.asymmetry > kMaxMirrorAsymmetry) {
    return absl::FailedPreconditionError(absl::StrCat(
        pose, " is not left/right symmetric: joint '", skeleton.joint(worst).name.substr(0, 128),
        "' lies ", mirror.asymmetry, " of the body's reach from the mirror image of '",
        skeleton.joint(mirror.partner[worst]).name.substr(0, 128), "' (at most ",
        kMaxMirrorAsymmetry, " allowed)"));
  }

  // -S is the half turn about the lateral axis; -S_j = G_partner^T (-S) G_j.
  const Quat half_turn(0, mirror.lateral.x(), mirror.lateral.y(), mirror.lateral.z());
  mirror.reflection.resize(count);
  for (int j = 0; j < count; ++j) {
    mirror.reflection[j] = orientation[mirror.partner[j]].conjugate() * half_turn * orientation[j];
  }
  return mirror;
}

absl::StatusOr<Clip> MirrorClip(const Clip& clip, const SkeletonMirror& mirror) {
  const Skeleton& skeleton = clip.skeleton();
  const int count = skeleton.joint_count();
  if (static_cast<int>(mirror.partner.size()) != count ||
      static_cast<int>(mirror.reflection.size()) != count) {
    return absl::InvalidArgumentError(absl::StrCat("the mirror is of a skeleton of ",
                                                   mirror.partner.size(),
                                                   " joints, the clip's has ", count));
  }
  const Quat world(0, mirror.lateral.x(), mirror.lateral.y(), mirror.lateral.z());
  // The reflection of each joint's parent frame: the world's for the root.
  std::vector<Quat> above(count);
  for (int j = 0; j < count; ++j) {
    const int parent = skeleton.joint(j).parent;
    above[j] = parent < 0 ? world : mirror.reflection[parent];
  }

  std::vector<Joint> joints = skeleton.joints();
  for (int j = 0; j < count; ++j) {
    const Joint& partner = skeleton.joint(mirror.partner[j]);
    joints[j].offset = ReflectBack(above[j], partner.offset);
    if (partner.end_site) joints[j].end_site = ReflectBack(mirror.reflection[j], *partner.end_site);
  }
  MOTIONDB_ASSIGN_OR_RETURN(Skeleton mirrored_skeleton, Skeleton::Create(std::move(joints)));

  const int frames = clip.frame_count();
  RowMatrixXd rotations(frames, clip.rotations().cols());
  RowMatrixXd positions(frames, clip.positions().cols());
  for (int f = 0; f < frames; ++f) {
    for (int j = 0; j < count; ++j) {
      const int partner = mirror.partner[j];
      const Quat q =
          (above[j].conjugate() * clip.rotation(f, partner) * mirror.reflection[j]).normalized();
      rotations.block<1, 4>(f, 4 * j) << q.w(), q.x(), q.y(), q.z();
      const int slot = skeleton.position_slot(j);
      if (slot < 0) continue;
      const int partner_slot = skeleton.position_slot(partner);
      const Eigen::Vector3d t =
          partner_slot >= 0 ? Eigen::Vector3d(clip.positions().block<1, 3>(f, 3 * partner_slot))
                            : skeleton.joint(partner).offset;
      positions.block<1, 3>(f, 3 * slot) = ReflectBack(above[j], t).transpose();
    }
  }
  return Clip::Create(std::make_shared<const Skeleton>(std::move(mirrored_skeleton)),
                      clip.frame_time(), std::move(rotations), std::move(positions));
}

}  // namespace motiondb
