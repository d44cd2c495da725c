// The body's facing (SPEC §2.4): the yaw about the vertical axis Y of the pelvis's global
// orientation, its removal from a pose, and its rate of change.
//
// The pelvis is the first joint from the root that branches (legs and spine). Files differ in
// where the facing lives: CMU turns the root `Hips` itself, Bandai keeps `joint_Root` still and
// turns `Hips` below it, so the facing is read from the pelvis's global orientation G (the
// product of the local rotations from the root down to the pelvis), never from one joint's
// channels.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_SPACE_HEADING_H_
#define MOTIONDB_CORE_SPACE_HEADING_H_

#include <Eigen/Core>

#include "core/motion/matrix.h"
#include "core/motion/rotation.h"
#include "core/motion/skeleton.h"

namespace motiondb {

// The first joint, walking down from the root, with two or more children; the root when the
// skeleton never branches.
int FindPelvis(const Skeleton& skeleton);

// The twist of `global` about Y in its swing-twist decomposition, normalize(w, 0, y, 0) with
// w >= 0: a turn about Y applied to `global` on either side turns the heading alike. Identity
// when undefined (the body upside down, w = y = 0).
Quat HeadingOf(const Quat& global);

// Rewrites `rotations` (frames x 4 * joints, w, x, y, z per joint) so that the pose no longer
// carries the facing: the joints above the pelvis become the identity (like the root position,
// they place the body) and the pelvis becomes HeadingOf(G)^-1 * G. Any turn about Y anywhere in
// the root chain then leaves the result unchanged. Returns the facing yaw of every frame in
// radians, unwrapped so that consecutive frames differ by less than pi.
Eigen::VectorXd RemoveHeading(const Skeleton& skeleton, RowMatrixXd* rotations);

// The yaw's rate of change in rad/s for frames sampled at `fps`: central differences (one-sided
// at the ends), then a centred moving average over `window` frames (fewer at the ends) to calm
// capture jitter. Zero for a single frame.
Eigen::VectorXd YawRate(const Eigen::VectorXd& yaw, double fps, int window);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_HEADING_H_
