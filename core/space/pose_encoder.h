// Pose vectors (SPEC §2.4-2.6, thesis 3.2.1): a frame's joint rotations, each linearised about
// its joint's reference orientation (the log map of conj(reference) * q in the hemisphere
// w >= 0), concatenated to 3 numbers per joint, plus the pelvis's yaw rate and (optionally) its
// velocity in the facing's frame when the facing is removed. The root position is not part of
// the pose.
//
// Two stages, so that a space can compute the references between them: ComputePoseRotations
// (facing removal, yaw rate) and EncodePoses (linearisation). Everything works on blocks of
// frames, one frame per row. Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_SPACE_POSE_ENCODER_H_
#define MOTIONDB_CORE_SPACE_POSE_ENCODER_H_

#include <Eigen/Core>

#include "absl/status/status.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"

namespace motiondb {

struct PoseOptions {
  // Remove the pelvis's facing (heading.h) and append its yaw rate as one extra dimension;
  // false keeps the raw local rotations, facing included, and adds no dimension.
  bool remove_heading = true;
  // Frames in the centred moving average that smooths the yaw rate (an even count acts as the
  // next odd one). At least 1.
  int yaw_rate_window = 5;
  // With the facing removed, also append the pelvis's horizontal velocity in the facing's frame
  // (two numbers, in the clip's leg lengths a second, smoothed like the yaw rate): it tells a
  // walk from a walk backwards or a run in another style, where limbs alone mislead
  // (root_velocity.h; bench/notes/2026-12-06-across-styles.md). Ignored with the facing kept.
  bool root_velocity = true;
};

absl::Status ValidatePoseOptions(const PoseOptions& options);

// Numbers per pose vector: 3 per joint, plus, when the facing is removed, 1 for the yaw rate and
// 2 for the root velocity if it is on.
int PoseDims(int joint_count, const PoseOptions& options);

// The rotations a pose describes, and the yaw rate that stands in for the removed facing.
struct PoseRotations {
  RowMatrixXd rotations;      // frames x 4 * joints, w, x, y, z per joint
  Eigen::VectorXd yaw_rate;   // rad/s per frame; empty when the facing is kept
  RowMatrixXd root_velocity;  // frames x 2, leg lengths/s in the facing's frame; empty when off
};

// Stage 1, for a clip already sampled at the rate the poses are wanted at.
PoseRotations ComputePoseRotations(const Clip& clip, const PoseOptions& options);

// Stage 2: frames x PoseDims pose vectors. `references` holds one unit quaternion per joint
// (joints x 4, w, x, y, z); the yaw rate, when present, follows the joints, then the root
// velocity's two columns.
RowMatrixXd EncodePoses(const PoseRotations& pose, const RowMatrixXd& references);

// The inverse of stage 2: pose vectors (frames x 3 * joints, or more columns, which are
// ignored: the yaw rate and root velocity do not shape the body) back to frames x 4 * joints
// rotations, each with w >= 0.
RowMatrixXd DecodePoses(const Eigen::Ref<const RowMatrixXd>& poses, const RowMatrixXd& references);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_POSE_ENCODER_H_
