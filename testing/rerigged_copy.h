// A Bandai take re-rigged as another studio's export of the same performance (issue 40 item 3's
// test rig): joints renamed as Mixamo names them, the root joint dropped so that the hips are
// the root, an extra spine joint between chest and neck, no toes, every joint's rest orientation
// turned (the rest pose changes: the upper arms hang 45 degrees down, an A-pose, the others turn
// by other angles), Euler order XYZ instead of ZXY, three rotation channels on every joint but
// the root, another unit and scale, and Z up instead of Y. The world positions of the joints it
// keeps are the original's turned to Z-up and scaled, frame for frame.
#ifndef MOTIONDB_TESTING_RERIGGED_COPY_H_
#define MOTIONDB_TESTING_RERIGGED_COPY_H_

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/rotation.h"

namespace motiondb::testing {

// The copy's scale: a centimetre of the original is this many of the copy's units.
inline constexpr double kRerigScale = 0.43;
// The turn that takes the original's Y-up world to the copy's Z-up one.
Quat RerigUpTurn();

// The copy of `clip`, a clip of the Bandai skeleton (joint_Root, Hips, Spine, Chest, Neck, Head,
// Shoulder_L, UpperArm_L, ..., Toes_R), written as BVH and read back.
absl::StatusOr<Clip> ReriggedCopy(const Clip& clip);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_RERIGGED_COPY_H_
