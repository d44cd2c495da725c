// Forward kinematics: every joint's world position on every frame of a clip, from the BVH's
// offsets, channels and rotation orders as the clip holds them (its quaternions were composed
// from each joint's Euler channels in the file's order).
//
// A joint's translation from its parent is its position channels' values when it has them (the
// root's; every joint's in files that give them all), its offset otherwise, the reading of
// Clip::root_position. World positions are in the file's units. Pure and thread-safe.
#ifndef MOTIONDB_CORE_MOTION_FORWARD_KINEMATICS_H_
#define MOTIONDB_CORE_MOTION_FORWARD_KINEMATICS_H_

#include "core/motion/clip.h"
#include "core/motion/matrix.h"

namespace motiondb {

// frames x (3 * joints): joint j's x, y, z on frame f in columns 3j..3j+2 of row f. Works joint
// by joint over every frame at once (parents precede their children).
RowMatrixXd ForwardKinematics(const Clip& clip);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_FORWARD_KINEMATICS_H_
