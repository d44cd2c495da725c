// The synthetic library's figure (testing/synthetic_corpus.h): its joints, and its poses as
// joint angles, the rest pose and each action's peak pose. Part of GenerateSyntheticCorpus.
#ifndef MOTIONDB_TESTING_INTERNAL_SYNTHETIC_FIGURE_H_
#define MOTIONDB_TESTING_INTERNAL_SYNTHETIC_FIGURE_H_

#include <array>
#include <numbers>

#include <Eigen/Core>

#include "core/motion/rotation.h"
#include "testing/synthetic_corpus.h"

namespace motiondb::testing::synthetic {

inline constexpr double kDeg = std::numbers::pi / 180.0;

// Joint indices of SyntheticSkeleton(), in its construction order.
enum JointIndex : int {
  kHips,
  kSpine,
  kChest,
  kNeck,
  kHead,
  kLeftCollar,
  kLeftShoulder,
  kLeftElbow,
  kLeftWrist,
  kRightCollar,
  kRightShoulder,
  kRightElbow,
  kRightWrist,
  kLeftHip,
  kLeftKnee,
  kLeftAnkle,
  kLeftToe,
  kRightHip,
  kRightKnee,
  kRightAnkle,
  kRightToe,
  kJointCount,
};

// Height of the hips above the floor (cm), so that the feet stand on y = 0: hip joint 4 below
// the pelvis, thigh 43, shin 42, ankle 8 above the floor.
inline constexpr double kHipHeight = 97.0;

// A pose as rotation angles (radians) about X, Y and Z per joint, composed in the skeleton's ZXY
// order: q = q_Z * q_X * q_Y. With arms hanging along -Y and the figure facing +Z: +X flexes the
// spine forward, -X swings a hanging arm (or forearm) forward, and +Z rotation lifts the outer
// end of the left collar (-Z the right one).
using Pose = std::array<Eigen::Vector3d, kJointCount>;

// The rotation of one joint of a Pose.
Quat JointRotation(const Eigen::Vector3d& xyz);

// Relaxed standing: arms slightly out from the body with soft elbows, knees slightly bent (the
// thigh, shin and foot angles cancel so the feet stay flat).
Pose RestPose();

// What each instance of an action draws for its peak pose.
struct PoseDraws {
  double lean;                  // radians, + forward
  Eigen::Vector3d left_target;  // hand-target offsets in metres (x left, y up, z forward)
  Eigen::Vector3d right_target;
  double slouch_depth;  // radians, total over spine, chest and neck
};

// The pose `action` peaks at, from `rest` with this instance's draws.
Pose PeakPose(SyntheticAction action, const PoseDraws& draws, const Pose& rest);

}  // namespace motiondb::testing::synthetic

#endif  // MOTIONDB_TESTING_INTERNAL_SYNTHETIC_FIGURE_H_
