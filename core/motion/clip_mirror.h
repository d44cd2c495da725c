// A clip's left/right mirror image: the same motion performed with the sides swapped, as seen in
// a mirror (a left-hand wave becomes a right-hand wave). From the skeleton's humanoid map
// (core/motion/humanoid_map.h): each joint takes its mirror partner's motion (a joint without a
// partner, on the body's midline, its own), reflected through the body's sagittal plane.
//
// The reflection. Take a pose of the skeleton that is left/right symmetric (its rest pose, or a
// mean pose when the rest pose is not a standing human, as Bandai's, whose every bone lies
// along its parent's x axis). Its world orientations G_j give each joint's local reflection
// S_j = G_partner(j)^T S G_j, S the world reflection across the pose's lateral axis (from the
// right slots to the left ones, square to the hips-head line). A joint's mirrored rotation is
// R'_j = S_parent(j)^T R_partner(j) S_j (S for the root's parent), its mirrored translation
// t'_j = S_parent(j)^T t_partner(j): its position channels, or its offset, so that the mirrored
// clip carries its own skeleton (the same joints, offsets swapped and reflected; bone offsets are
// per clip anyway). Then every mirrored joint's world position is exactly the world position of
// its partner reflected by S (x'_j = S x_partner(j)), and mirroring twice gives the clip back.
// When the rest pose's local frames agree with the world's (CMU, Mixamo, most BVH), every S_j is
// S and the rotation is the familiar R' = S R_partner S. The reference pose fixes what offsets
// alone cannot: the twist of each joint's frame about its bone.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_MOTION_CLIP_MIRROR_H_
#define MOTIONDB_CORE_MOTION_CLIP_MIRROR_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/humanoid_map.h"
#include "core/motion/matrix.h"
#include "core/motion/rotation.h"
#include "core/motion/skeleton.h"

namespace motiondb {

// How a skeleton's poses mirror: each joint's partner and local reflection. A reflection R
// (det -1) is held as the rotation -R's quaternion.
struct SkeletonMirror {
  std::vector<int> partner;      // by joint: its mirror partner, itself on the midline
  Eigen::Vector3d lateral;       // the world reflection's axis (unit): S = I - 2 l l^T
  std::vector<Quat> reflection;  // by joint: -S_j as a rotation
  double asymmetry = 0;          // the reference pose's, as MakeSkeletonMirror measures it
};

// The reference pose's asymmetry allowed: the largest distance of a joint from its partner's
// mirror image, as a share of the pose's reach (the farthest joint from the hips).
inline constexpr double kMaxMirrorAsymmetry = 0.1;

// The mirror of `skeleton` mapped by `map`, with `reference` (joints x 4, each joint's local
// rotation as w, x, y, z) as its symmetric pose; an empty `reference` is the rest pose (every
// rotation the identity). FAILED_PRECONDITION, saying why, when the map cannot mirror: required
// slots missing (named), a joint whose partner's parent is not its parent's partner, a joint
// without a partner under a parent that has one, or a reference pose whose joints lie farther
// than kMaxMirrorAsymmetry from their partners' mirror images (the worst named).
// INVALID_ARGUMENT for a `reference` of the wrong shape.
absl::StatusOr<SkeletonMirror> MakeSkeletonMirror(const Skeleton& skeleton, const HumanoidMap& map,
                                                  const RowMatrixXd& reference = {});

// `clip` mirrored: its skeleton's joints, offsets and channels mirrored as above, every frame's
// rotations and translations mirrored. `mirror` must be of the clip's skeleton (the same joint
// count; INVALID_ARGUMENT otherwise).
absl::StatusOr<Clip> MirrorClip(const Clip& clip, const SkeletonMirror& mirror);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_CLIP_MIRROR_H_
