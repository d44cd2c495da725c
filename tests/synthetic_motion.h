// A small humanoid (spine, arms, legs) and sinusoidal motion on it, for the space tests.
#ifndef MOTIONDB_TESTS_SYNTHETIC_MOTION_H_
#define MOTIONDB_TESTS_SYNTHETIC_MOTION_H_

#include <memory>
#include <string>
#include <vector>

#include "core/motion/clip.h"

namespace motiondb::testing {

// Hips (pelvis: spine and two legs) -> Spine -> Chest -> Neck -> Head, Chest -> arms
// (Shoulder, UpperArm, LowerArm, Hand), Hips -> legs (UpperLeg, LowerLeg, Foot). With
// `still_root`, a `Root` joint sits above Hips as in Bandai's files; otherwise Hips is the root
// as in CMU's. Leaves end in End Sites of zero length, as in Bandai's files.
std::shared_ptr<const Skeleton> HumanoidSkeleton(bool still_root);

// The indices of the joints whose name contains "Leg" or "Foot".
std::vector<int> LegJoints(const Skeleton& skeleton);

struct SyntheticMotion {
  int frames = 120;
  double fps = 60.0;
  double arm_amplitude = 0.6;   // radians, on the arms
  double leg_amplitude = 0.3;   // radians, on the legs
  double body_amplitude = 0.1;  // radians, on the spine, neck and head
  double turn_rate = 0.0;       // rad/s of the pelvis about the vertical axis
  int seed = 1;                 // varies the frequencies and phases
};

// Every joint below the pelvis swings about its own axis with its own frequency (three
// incommensurate sinusoids per joint, so the poses span every dimension); the pelvis tilts
// slightly and turns at `turn_rate`; a still root never rotates.
Clip SyntheticClip(std::shared_ptr<const Skeleton> skeleton, const SyntheticMotion& motion = {});

// `clip` turned by `angle` radians about the vertical axis through the origin: the pelvis's
// global orientation G' = R_y(angle) * G (its local rotation adjusted through its ancestors),
// and the translations of the root-to-pelvis chain turned so that their world positions turn.
Clip TurnedClip(const Clip& clip, double angle);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTS_SYNTHETIC_MOTION_H_
