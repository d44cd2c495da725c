// A skeleton's canonical humanoid map: which of its joints plays each slot of a humanoid (the
// hips, spine, head, and each side's upper leg, lower leg, foot, upper arm, forearm and hand that
// HumanIK and VRM require; optionally the chest, neck, shoulders and toes), and which joints are
// left/right mirror pairs. What lets motion of one rig be compared with, or mirrored onto,
// another's.
//
// The map comes from the joints' names and the hierarchy. Names are read as tokens (a namespace
// prefix before ':' or '|' dropped, case and separators ignored, camelCase split): the aliases
// of Mixamo, MotionBuilder/HumanIK, CMU (BVH and ASF), Bandai, 3ds Max Biped, the Unreal
// mannequin and VRM. The hierarchy settles what names leave ambiguous (CMU's 3ds Max export calls
// the upper arm "LeftShoulder" below a "LeftCollar": each limb's slots must form a chain down
// the tree, and the assignment filling most of them wins) and fills slots no name settles (the
// joint between two mapped slots, a chain's next joint, the branch of the arms for the chest).
// A joint's side comes from its name (Left/L/_l/l_, "lhand"); failing that, from the sign of
// its rest position across the body's lateral axis (see MapHumanoid).
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_MOTION_HUMANOID_MAP_H_
#define MOTIONDB_CORE_MOTION_HUMANOID_MAP_H_

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/skeleton.h"

namespace motiondb {

// The canonical slots, named as VRM names its humanoid bones (capitalised).
enum class HumanoidSlot {
  kHips,
  kSpine,
  kChest,
  kNeck,
  kHead,
  kLeftShoulder,
  kLeftUpperArm,
  kLeftLowerArm,
  kLeftHand,
  kRightShoulder,
  kRightUpperArm,
  kRightLowerArm,
  kRightHand,
  kLeftUpperLeg,
  kLeftLowerLeg,
  kLeftFoot,
  kLeftToes,
  kRightUpperLeg,
  kRightLowerLeg,
  kRightFoot,
  kRightToes,
};
inline constexpr int kHumanoidSlotCount = 21;

// "Hips", "LeftUpperArm", ...
absl::string_view HumanoidSlotName(HumanoidSlot slot);
// The slot of a name HumanoidSlotName gives, case ignored; nullopt for any other text.
std::optional<HumanoidSlot> ParseHumanoidSlot(absl::string_view name);
// One of the 15 slots HumanIK and VRM require.
bool IsRequiredSlot(HumanoidSlot slot);
// Every slot, in enum order.
const std::array<HumanoidSlot, kHumanoidSlotCount>& AllHumanoidSlots();

// A slot given its joint by hand (by the joint's name), for a skeleton the automatic map gets
// wrong.
struct SlotOverride {
  HumanoidSlot slot = HumanoidSlot::kHips;
  std::string joint;
};

struct HumanoidMap {
  // The joint index of each slot (indexed by the enum), or -1 when no joint plays it.
  std::array<int, kHumanoidSlotCount> joints{};
  // Every left/right mirror pair of joints (left first), not only the slots': CMU's LHipJoint
  // and RHipJoint, the fingers, ...; ordered by the left joint's index.
  std::vector<std::pair<int, int>> mirror_pairs;
  // The required slots without a joint, in enum order; empty when the map is complete.
  std::vector<HumanoidSlot> missing;

  int joint(HumanoidSlot slot) const { return joints[static_cast<int>(slot)]; }
  bool complete() const { return missing.empty(); }
};

// Maps `skeleton`'s joints to the slots. `overrides` are applied first and the automatic map
// fills the other slots around them (an overridden upper arm makes its child the forearm), so
// one override can mend a chain. INVALID_ARGUMENT naming the override for a joint the skeleton
// lacks, or a slot or joint given twice. Deterministic: the same skeleton and overrides give
// the same map.
//
// A joint whose name carries no side takes the side of its rest position (the sum of the
// offsets from the hips, the BVH rest pose) along the body's left direction: up x forward, up
// from the hips to the head, forward the feet's direction (foot to toe), right-handed as BVH,
// FBX and glTF are. Names are tried first because rest poses are not reliable: Bandai's BVH
// rest pose lays every bone along its parent's x axis, so its left leg's offset is no more
// "left" than its right's. Without feet to give the forward direction, +X is taken as left,
// BVH's habit (Y up, facing +Z, as CMU and Mixamo export); when +X lies along the up direction
// too (Bandai's rest pose, without its names), no side is guessed: the limbs are left missing.
absl::StatusOr<HumanoidMap> MapHumanoid(const Skeleton& skeleton,
                                        const std::vector<SlotOverride>& overrides = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_HUMANOID_MAP_H_
