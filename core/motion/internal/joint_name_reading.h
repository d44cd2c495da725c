// What a joint's name says of it to the humanoid map (core/motion/humanoid_map.h): its side, the
// body part its aliases name, and a key that its mirror joint's name shares.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_MOTION_INTERNAL_JOINT_NAME_READING_H_
#define MOTIONDB_CORE_MOTION_INTERNAL_JOINT_NAME_READING_H_

#include <string>

#include "absl/strings/string_view.h"

namespace motiondb {

enum class BodySide { kNone, kLeft, kRight };

// The parts of a humanoid that joint names name; a sided part takes its side from the name.
enum class BodyPart {
  kNone,
  kHips,
  kSpine,
  kChest,
  kNeck,
  kHead,
  kShoulder,
  kUpperArm,
  kLowerArm,
  kHand,
  kUpperLeg,
  kLowerLeg,
  kFoot,
  kToes,
};

struct JointNameReading {
  BodySide side = BodySide::kNone;
  BodyPart part = BodyPart::kNone;
  // The name's tokens without its side, joined by '_' ("LeftHandIndex1" -> "hand_index_1",
  // "lhand" -> "hand"): a left joint and its right mirror share it.
  std::string mirror_key;
};

// Reads a joint name: a namespace before the last ':' or '|' dropped ("mixamorig:"), tokens
// split at separators, camelCase and digits, case ignored. A side is a token "left", "l",
// "right" or "r", or one prefixed to a body word ("lefthand", "lhand", "rfemur"). The part is
// the tokens without side, digits and rig prefixes ("Bip01", "Character1") matched whole against
// the aliases ("LeftUpLeg", "thigh_l", "UpperLeg_L", "LeftHip" -> upper leg), so that
// "LeftHandThumb1" or "lowerarm_twist_01_l" name no part.
JointNameReading ReadJointName(absl::string_view name);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_INTERNAL_JOINT_NAME_READING_H_
