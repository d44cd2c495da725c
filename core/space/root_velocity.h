// The pelvis's horizontal velocity seen from the body's facing: the part of a motion that the
// joint rotations do not hold once the facing is removed (heading.h), e.g. whether a walk goes
// forwards, sideways or backwards, and how fast. In leg lengths a second, so that actors of
// different sizes moving alike give the same numbers.
#ifndef MOTIONDB_CORE_SPACE_ROOT_VELOCITY_H_
#define MOTIONDB_CORE_SPACE_ROOT_VELOCITY_H_

#include "core/motion/clip.h"
#include "core/motion/matrix.h"

namespace motiondb {

// Forward and sideways, in the facing's frame.
inline constexpr int kRootVelocityDims = 2;

// A leg's length, in the file's units: the median over the pelvis's children (heading.h's
// FindPelvis; two legs and a spine in a humanoid) of the longest chain of bone lengths down from
// each, End Sites included. 1 when that is 0 (a lone joint).
double LegLength(const Skeleton& skeleton);

// frames x kRootVelocityDims: the pelvis's velocity in the Y-up ground plane (X, Z), turned by
// -yaw[f] into the facing's frame and divided by LegLength, differentiated and smoothed as
// YawRate does with `window`. `yaw` is RemoveHeading's, one per frame. Thread-safe.
RowMatrixXd RootVelocity(const Clip& clip, const Eigen::VectorXd& yaw, int window);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_ROOT_VELOCITY_H_
