// Canonical pose vectors: a pose told by the directions of a humanoid's bones rather than by its
// joints' rotations, so that skeletons with other joint names, rotation orders, channel layouts,
// units, bone lengths, up axes and rest poses describe one motion with the same numbers, and one
// space can hold the clips of several rigs (issue 40 item 3).
//
// A bone runs between two canonical slots (humanoid_map.h): each leg's thigh and shin, each
// arm's upper arm and forearm, the trunk (from between the hips to between the shoulders), the
// neck (from between the shoulders to the head) and the shoulder line (right to left shoulder).
// Each is a unit direction of its world positions (forward_kinematics.h), so that bone lengths,
// units and where a rig puts a joint along a bone do not count; the rest pose never enters.
// Directions are told in the body's heading frame: its up axis, its left (the hips' line from the
// right upper leg to the left, made horizontal) and forward = left x up. The yaw rate (rad/s
// about up) and the velocity of the point between the hips (leg lengths a second, leftwards and
// forwards) follow, smoothed as pose_encoder.h's are.
//
// The up axis is read from the motion, not from the file: the world axis (+-X, Y or Z) nearest
// the clip's mean trunk direction. Rest poses cannot tell it (Bandai's lays every bone along its
// parent's x axis), and a person's trunk points up for most of any capture; a clip whose body
// lies down throughout would be read wrongly, which is why the axis is taken over the whole
// clip and never per frame.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_SPACE_CANONICAL_POSE_H_
#define MOTIONDB_CORE_SPACE_CANONICAL_POSE_H_

#include <functional>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"
#include "core/motion/humanoid_map.h"
#include "core/motion/matrix.h"
#include "core/space/pose_encoder.h"

namespace motiondb {

// What a space's pose vectors are made of.
enum class SpaceRepresentation {
  kJointRotations,  // pose_encoder.h: one skeleton's joint rotations (every space before this)
  kCanonicalBones,  // this file: bone directions of any mapped humanoid
};

// "joint-rotations" or "canonical-bones"; ParseSpaceRepresentation reads either.
absl::string_view SpaceRepresentationName(SpaceRepresentation representation);
absl::StatusOr<SpaceRepresentation> ParseSpaceRepresentation(absl::string_view name);

inline constexpr int kCanonicalBoneCount = 11;

// The bone's name, its humanoid slot's (humanoid_map.h): "LeftUpperLeg" (the thigh),
// "LeftLowerLeg", ..., "RightLowerArm", "Spine" (hips to shoulders), "Neck", and "Shoulders" (the
// shoulder line).
absl::string_view CanonicalBoneName(int bone);

// How a skeleton's joints are found: its humanoid map (with any overrides its owner stores).
using HumanoidMapper = std::function<absl::StatusOr<HumanoidMap>(const Skeleton& skeleton)>;

// OK when `map` gives a joint to every slot the bones use (all required slots but the spine);
// else FAILED_PRECONDITION naming `skeleton_name` and the missing slots.
absl::Status CheckCanonicalMap(const HumanoidMap& map, absl::string_view skeleton_name);

// Numbers per canonical pose vector: 3 per bone, 1 for the yaw rate and, when
// options.root_velocity, 2 for the velocity. options.remove_heading must be true.
int CanonicalPoseDims(const PoseOptions& options);

// frames x CanonicalPoseDims: the clip's poses, for a clip already sampled at the rate wanted.
// `map` must pass CheckCanonicalMap.
RowMatrixXd CanonicalPoses(const Clip& clip, const HumanoidMap& map, const PoseOptions& options);

// `poses` (CanonicalPoses' with `options`) turned into the poses of the clip's left/right mirror
// image, as CanonicalPoses would give for the clip mirrored through any vertical plane
// (clip_mirror.h): each bone takes its partner's direction (the shoulder line its own, reversed)
// with its leftward part negated, and the yaw rate and leftward velocity change sign. The
// heading frame is the mirror's own (the hips' line stays its left), which is why no plane
// needs choosing. Mirroring twice gives the poses back. INVALID_ARGUMENT for poses of another
// width.
absl::Status MirrorCanonicalPoses(const PoseOptions& options, RowMatrixXd* poses);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_CANONICAL_POSE_H_
