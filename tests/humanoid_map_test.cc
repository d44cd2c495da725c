#include "core/motion/humanoid_map.h"

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/bvh/bvh_reader.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using Slot = HumanoidSlot;

// The slot -> joint name a map gives, for the mapped slots.
std::map<std::string, std::string> SlotNames(const Skeleton& skeleton, const HumanoidMap& map) {
  std::map<std::string, std::string> named;
  for (const Slot slot : AllHumanoidSlots()) {
    if (map.joint(slot) >= 0) {
      named[std::string(HumanoidSlotName(slot))] = skeleton.joint(map.joint(slot)).name;
    }
  }
  return named;
}

std::set<std::pair<std::string, std::string>> PairNames(const Skeleton& skeleton,
                                                        const HumanoidMap& map) {
  std::set<std::pair<std::string, std::string>> pairs;
  for (const auto& [left, right] : map.mirror_pairs) {
    pairs.emplace(skeleton.joint(left).name, skeleton.joint(right).name);
  }
  return pairs;
}

std::string MissingText(const HumanoidMap& map) {
  std::vector<std::string> names;
  for (const Slot slot : map.missing) names.emplace_back(HumanoidSlotName(slot));
  return absl::StrJoin(names, ",");
}

// The 21 slots' names for one rig, in slot order, and the names of both sides' limbs from
// `left` and `right` patterns: "{}" stands for the part.
struct RigNames {
  std::string hips, spine, chest, neck, head;
  std::array<std::string, 8> left;  // shoulder, upper arm, forearm, hand, upper leg, lower
                                    // leg, foot, toes
  std::array<std::string, 8> right;
};

// Slot order of the template joints below: the slot enum's.
std::map<std::string, std::string> Expected(const RigNames& names) {
  const std::array<std::string, 5> center = {names.hips, names.spine, names.chest, names.neck,
                                             names.head};
  std::map<std::string, std::string> expected;
  for (int i = 0; i < 5; ++i) {
    expected[std::string(HumanoidSlotName(static_cast<Slot>(i)))] = center[i];
  }
  const std::array<Slot, 8> left = {Slot::kLeftShoulder, Slot::kLeftUpperArm, Slot::kLeftLowerArm,
                                    Slot::kLeftHand,     Slot::kLeftUpperLeg, Slot::kLeftLowerLeg,
                                    Slot::kLeftFoot,     Slot::kLeftToes};
  const std::array<Slot, 8> right = {
      Slot::kRightShoulder, Slot::kRightUpperArm, Slot::kRightLowerArm, Slot::kRightHand,
      Slot::kRightUpperLeg, Slot::kRightLowerLeg, Slot::kRightFoot,     Slot::kRightToes};
  for (int i = 0; i < 8; ++i) {
    expected[std::string(HumanoidSlotName(left[i]))] = names.left[i];
    expected[std::string(HumanoidSlotName(right[i]))] = names.right[i];
  }
  return expected;
}

struct ExtraJoint {
  std::string name, parent;
  Eigen::Vector3d offset;
};

// A humanoid in a T-pose (Y up, facing +Z, its left at +X; centimetres), named by `names`,
// under `root` when given, with `extras` (twist joints, fingers, ...) added after. `facing_back`
// turns it to face -Z (its left then at -X).
Skeleton Humanoid(const RigNames& names, const std::vector<ExtraJoint>& extras = {},
                  const std::string& root = "", bool facing_back = false) {
  std::vector<Joint> joints;
  const double turn = facing_back ? -1 : 1;
  const auto add = [&](const std::string& name, const std::string& parent, double x, double y,
                       double z) {
    Joint joint;
    joint.name = name;
    joint.parent = -1;
    for (size_t i = 0; i < joints.size(); ++i) {
      if (joints[i].name == parent) joint.parent = static_cast<int>(i);
    }
    joint.offset = Eigen::Vector3d(turn * x, y, turn * z);
    joint.channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
    joints.push_back(joint);
  };
  if (!root.empty()) add(root, "", 0, 0, 0);
  add(names.hips, root, 0, 95, 0);
  add(names.spine, names.hips, 0, 10, 0);
  add(names.chest, names.spine, 0, 12, 0);
  add(names.neck, names.chest, 0, 20, 0);
  add(names.head, names.neck, 0, 9, 0);
  for (const double side : {1.0, -1.0}) {
    const std::array<std::string, 8>& limb = side > 0 ? names.left : names.right;
    add(limb[0], names.chest, side * 3, 16, 0);
    add(limb[1], limb[0], side * 10, 0, 0);
    add(limb[2], limb[1], side * 28, 0, 0);
    add(limb[3], limb[2], side * 25, 0, 0);
  }
  for (const double side : {1.0, -1.0}) {
    const std::array<std::string, 8>& limb = side > 0 ? names.left : names.right;
    add(limb[4], names.hips, side * 9, -5, 0);
    add(limb[5], limb[4], 0, -42, 0);
    add(limb[6], limb[5], 0, -40, 0);
    add(limb[7], limb[6], 0, -6, 12);
  }
  for (const ExtraJoint& extra : extras) {
    add(extra.name, extra.parent, extra.offset.x(), extra.offset.y(), extra.offset.z());
  }
  absl::StatusOr<Skeleton> skeleton = Skeleton::Create(std::move(joints));
  EXPECT_TRUE(skeleton.ok()) << skeleton.status();
  return *std::move(skeleton);
}

// Names with a prefix and a per-side pattern: Sided("mixamorig:", "Left", "Right", ...).
RigNames Rig(const std::string& prefix, const std::array<std::string, 5>& center,
             const std::string& left, const std::string& right,
             const std::array<std::string, 8>& parts, bool side_last = false) {
  RigNames names;
  names.hips = prefix + center[0];
  names.spine = prefix + center[1];
  names.chest = prefix + center[2];
  names.neck = prefix + center[3];
  names.head = prefix + center[4];
  for (int i = 0; i < 8; ++i) {
    names.left[i] = side_last ? prefix + parts[i] + left : prefix + left + parts[i];
    names.right[i] = side_last ? prefix + parts[i] + right : prefix + right + parts[i];
  }
  return names;
}

void ExpectMapsTo(const Skeleton& skeleton, const std::map<std::string, std::string>& expected) {
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(skeleton);
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_TRUE(map->complete()) << "missing " << MissingText(*map);
  EXPECT_EQ(SlotNames(skeleton, *map), expected);
}

TEST(HumanoidMap, SlotNamesParseBackCaseIgnored) {
  EXPECT_EQ(ParseHumanoidSlot("LeftHand"), Slot::kLeftHand);
  EXPECT_EQ(ParseHumanoidSlot("leftupperleg"), Slot::kLeftUpperLeg);
  EXPECT_EQ(ParseHumanoidSlot("Tail"), std::nullopt);
  int required = 0;
  for (const Slot slot : AllHumanoidSlots()) {
    EXPECT_EQ(ParseHumanoidSlot(HumanoidSlotName(slot)), slot);
    required += IsRequiredSlot(slot) ? 1 : 0;
  }
  EXPECT_EQ(required, 15);
}

TEST(HumanoidMap, MixamoNamesWithTheirPrefix) {
  const RigNames names =
      Rig("mixamorig:", {"Hips", "Spine", "Spine1", "Neck", "Head"}, "Left", "Right",
          {"Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase"});
  const Skeleton skeleton =
      Humanoid(names, {{"mixamorig:HeadTop_End", "mixamorig:Head", {0, 18, 0}},
                       {"mixamorig:LeftHandIndex1", "mixamorig:LeftHand", {4, 0, 1}},
                       {"mixamorig:LeftHandIndex2", "mixamorig:LeftHandIndex1", {3, 0, 0}},
                       {"mixamorig:RightHandIndex1", "mixamorig:RightHand", {-4, 0, 1}},
                       {"mixamorig:RightHandIndex2", "mixamorig:RightHandIndex1", {-3, 0, 0}},
                       {"mixamorig:LeftToe_End", "mixamorig:LeftToeBase", {0, 0, 5}},
                       {"mixamorig:RightToe_End", "mixamorig:RightToeBase", {0, 0, 5}}});
  ExpectMapsTo(skeleton, Expected(names));
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(skeleton);
  ASSERT_TRUE(map.ok());
  // Every sided joint pairs, the fingers and toe ends too: 8 limb joints and 3 extras a side.
  EXPECT_EQ(map->mirror_pairs.size(), 11u);
  EXPECT_TRUE(PairNames(skeleton, *map)
                  .contains({"mixamorig:LeftHandIndex2", "mixamorig:RightHandIndex2"}));
}

TEST(HumanoidMap, UnrealMannequinNamesUnderItsRoot) {
  const RigNames names =
      Rig("", {"pelvis", "spine_01", "spine_02", "neck_01", "head"}, "_l", "_r",
          {"clavicle", "upperarm", "lowerarm", "hand", "thigh", "calf", "foot", "ball"},
          /*side_last=*/true);
  // Twist bones hang beside the limbs, and the IK bones under the root name feet.
  const Skeleton skeleton = Humanoid(names,
                                     {{"upperarm_twist_01_l", "upperarm_l", {5, 0, 0}},
                                      {"lowerarm_twist_01_l", "lowerarm_l", {12, 0, 0}},
                                      {"upperarm_twist_01_r", "upperarm_r", {-5, 0, 0}},
                                      {"lowerarm_twist_01_r", "lowerarm_r", {-12, 0, 0}},
                                      {"thigh_twist_01_l", "thigh_l", {0, -20, 0}},
                                      {"thigh_twist_01_r", "thigh_r", {0, -20, 0}},
                                      {"ik_foot_root", "root", {0, 0, 0}},
                                      {"ik_foot_l", "ik_foot_root", {9, 8, 0}},
                                      {"ik_foot_r", "ik_foot_root", {-9, 8, 0}}},
                                     "root");
  ExpectMapsTo(skeleton, Expected(names));
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(skeleton);
  ASSERT_TRUE(map.ok());
  const auto pairs = PairNames(skeleton, *map);
  EXPECT_TRUE(pairs.contains({"thigh_twist_01_l", "thigh_twist_01_r"}));
  EXPECT_TRUE(pairs.contains({"ik_foot_l", "ik_foot_r"}));
}

TEST(HumanoidMap, VrmNames) {
  const RigNames names =
      Rig("", {"hips", "spine", "chest", "neck", "head"}, "left", "right",
          {"Shoulder", "UpperArm", "LowerArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "Toes"});
  ExpectMapsTo(Humanoid(names), Expected(names));
}

TEST(HumanoidMap, VroidNamesWithCentreAndSideMarks) {
  const RigNames names =
      Rig("J_Bip_", {"C_Hips", "C_Spine", "C_Chest", "C_Neck", "C_Head"}, "L_", "R_",
          {"Shoulder", "UpperArm", "LowerArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "ToeBase"});
  ExpectMapsTo(Humanoid(names), Expected(names));
}

// joint1..joint21: the hierarchy finds the hips (three tall subtrees), the arms' branch (the
// chest), limbs by their bone lengths, and the sides from the rest pose.
RigNames MeaninglessNames() {
  RigNames names;
  int next = 1;
  const auto take = [&] { return absl::StrCat("joint", next++); };
  names.hips = take();
  names.spine = take();
  names.chest = take();
  names.neck = take();
  names.head = take();
  for (std::string& name : names.left) name = take();
  for (std::string& name : names.right) name = take();
  return names;
}

TEST(HumanoidMap, MeaninglessNamesMapFromTheHierarchyAndRestPose) {
  const RigNames names = MeaninglessNames();
  ExpectMapsTo(Humanoid(names), Expected(names));
}

TEST(HumanoidMap, MeaninglessNamesFacingBackTakeTheirLeftFromTheFeet) {
  // Turned to face -Z, the body's left is at -X: the toes' direction tells it.
  const RigNames names = MeaninglessNames();
  ExpectMapsTo(Humanoid(names, {}, "", /*facing_back=*/true), Expected(names));
}

TEST(HumanoidMap, ASkeletonThatIsNoHumanoidSaysWhatIsMissing) {
  std::vector<Joint> joints(3);
  for (int i = 0; i < 3; ++i) {
    joints[i].name = absl::StrCat("joint", i + 1);
    joints[i].parent = i - 1;
    joints[i].offset = Eigen::Vector3d(0, i == 0 ? 0 : 10, 0);
  }
  const absl::StatusOr<Skeleton> chain = Skeleton::Create(std::move(joints));
  ASSERT_TRUE(chain.ok());
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(*chain);
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_FALSE(map->complete());
  EXPECT_EQ(map->missing.size(), 15u) << MissingText(*map);
  EXPECT_TRUE(map->mirror_pairs.empty());
}

TEST(HumanoidMap, ArmlessSkeletonListsOnlyTheArmsAsMissing) {
  const RigNames names =
      Rig("", {"Hips", "Spine", "Chest", "Neck", "Head"}, "Left", "Right",
          {"Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase"});
  const Skeleton whole = Humanoid(names);
  // Without the joints below the shoulders, parents renumbered.
  std::vector<Joint> joints;
  std::vector<int> renumbered(whole.joint_count(), -1);
  for (int j = 0; j < whole.joint_count(); ++j) {
    Joint joint = whole.joint(j);
    if (absl::StrContains(joint.name, "Arm") || absl::StrContains(joint.name, "Hand")) continue;
    if (joint.parent >= 0) joint.parent = renumbered[joint.parent];
    renumbered[j] = static_cast<int>(joints.size());
    joints.push_back(std::move(joint));
  }
  const absl::StatusOr<Skeleton> armless = Skeleton::Create(std::move(joints));
  ASSERT_TRUE(armless.ok()) << armless.status();
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(*armless);
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_EQ(MissingText(*map),
            "LeftUpperArm,LeftLowerArm,LeftHand,RightUpperArm,RightLowerArm,RightHand");
}

TEST(HumanoidMap, OverridesPinSlotsAndTheRestFollows) {
  const RigNames names = MeaninglessNames();
  const Skeleton skeleton = Humanoid(names);
  // The hands swapped by hand: each arm's chain follows its hand up, so the arms swap.
  const absl::StatusOr<HumanoidMap> map =
      MapHumanoid(skeleton, {{Slot::kLeftHand, names.right[3]}, {Slot::kRightHand, names.left[3]}});
  ASSERT_TRUE(map.ok()) << map.status();
  RigNames swapped = names;
  for (int i = 0; i < 4; ++i) std::swap(swapped.left[i], swapped.right[i]);
  EXPECT_EQ(SlotNames(skeleton, *map), Expected(swapped));
}

TEST(HumanoidMap, BadOverridesAreRefusedNamingThem) {
  const RigNames names = MeaninglessNames();
  const Skeleton skeleton = Humanoid(names);
  const absl::StatusOr<HumanoidMap> unknown = MapHumanoid(skeleton, {{Slot::kLeftHand, "hand_l"}});
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(unknown.status().message(),
            "overrides[0] (LeftHand=hand_l): the skeleton has no joint named 'hand_l'");
  const absl::StatusOr<HumanoidMap> twice =
      MapHumanoid(skeleton, {{Slot::kLeftHand, "joint9"}, {Slot::kRightHand, "joint9"}});
  EXPECT_EQ(twice.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(twice.status().message(),
            "overrides[1] (RightHand=joint9): the joint is given to two slots");
}

TEST(HumanoidMap, IsDeterministic) {
  const RigNames names = MeaninglessNames();
  const Skeleton skeleton = Humanoid(names);
  const absl::StatusOr<HumanoidMap> first = MapHumanoid(skeleton);
  const absl::StatusOr<HumanoidMap> second = MapHumanoid(skeleton);
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(first->joints, second->joints);
  EXPECT_EQ(first->mirror_pairs, second->mirror_pairs);
}

// The real skeletons: what each file's names mean, checked joint by joint.
struct RealRig {
  std::string file;  // under ../shared/mocap
  RigNames names;
  size_t pairs;  // every joint with a side pairs with its mirror
};

std::vector<RealRig> RealRigs() {
  // CMU as 3ds Max converted it: the upper arm is "LeftShoulder" below "LeftCollar", the hand
  // "LeftWrist" above "lhand"; the chest is where the collars branch off.
  const RigNames cmu_3dsmax =
      Rig("", {"Hips", "lowerback", "Chest2", "lowerneck", "Head"}, "Left", "Right",
          {"Collar", "Shoulder", "Elbow", "Wrist", "Hip", "Knee", "Ankle", "Toe"});
  const RigNames motionbuilder =
      Rig("", {"Hips", "LowerBack", "Spine1", "Neck", "Head"}, "Left", "Right",
          {"Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase"});
  const RigNames retarget =
      Rig("", {"Hips", "Spine", "Spine3", "Neck", "Head"}, "Left", "Right",
          {"Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase"});
  const RigNames bandai =
      Rig("", {"Hips", "Spine", "Chest", "Neck", "Head"}, "_L", "_R",
          {"Shoulder", "UpperArm", "LowerArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "Toes"},
          /*side_last=*/true);
  return {
      {"cmu/01_01_3dsmax.bvh", cmu_3dsmax, 12},
      {"cmu/14_14.bvh", cmu_3dsmax, 12},
      {"cmu/jumpingjacks.bvh", cmu_3dsmax, 12},
      {"cmu/01_01_motionbuilder.bvh", motionbuilder, 12},
      {"other-skeletons/cmu1006_walking.bvh", retarget, 10},
      {"bandai1/dataset-1_bow_active_001.bvh", bandai, 8},
      {"bandai2-normal/dataset-2_walk_normal_001.bvh", bandai, 8},
  };
}

TEST(HumanoidMap, EveryRealSkeletonMapsItsFifteenRequiredSlots) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  for (const RealRig& rig : RealRigs()) {
    SCOPED_TRACE(rig.file);
    const absl::StatusOr<BvhReadResult> read = ReadBvhFile((mocap / rig.file).string());
    ASSERT_TRUE(read.ok()) << read.status();
    const Skeleton& skeleton = read->clip.skeleton();
    ExpectMapsTo(skeleton, Expected(rig.names));
    const absl::StatusOr<HumanoidMap> map = MapHumanoid(skeleton);
    ASSERT_TRUE(map.ok());
    EXPECT_EQ(map->mirror_pairs.size(), rig.pairs);
  }
}

TEST(HumanoidMap, CmuPairsItsHelperJoints) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  const absl::StatusOr<BvhReadResult> read = ReadBvhFile((mocap / "cmu/01_01_3dsmax.bvh").string());
  ASSERT_TRUE(read.ok()) << read.status();
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(read->clip.skeleton());
  ASSERT_TRUE(map.ok());
  const auto pairs = PairNames(read->clip.skeleton(), *map);
  for (const auto& pair :
       std::vector<std::pair<std::string, std::string>>{{"LHipJoint", "RHipJoint"},
                                                        {"lhand", "rhand"},
                                                        {"LFingers", "RFingers"},
                                                        {"LThumb", "RThumb"},
                                                        {"LeftCollar", "RightCollar"}}) {
    EXPECT_TRUE(pairs.contains(pair)) << pair.first;
  }
}

TEST(HumanoidMap, EveryFileOfTheCorpusMapsCompletely) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  for (const char* folder : {"cmu", "other-skeletons", "bandai1", "bandai2-normal"}) {
    for (const std::filesystem::path& file : testing::BvhFilesUnder(mocap / folder)) {
      const absl::StatusOr<BvhReadResult> read = ReadBvhFile(file.string());
      ASSERT_TRUE(read.ok()) << read.status();
      const absl::StatusOr<HumanoidMap> map = MapHumanoid(read->clip.skeleton());
      ASSERT_TRUE(map.ok()) << map.status();
      EXPECT_TRUE(map->complete()) << file << " misses " << MissingText(*map);
    }
  }
}

// The skeleton with every name replaced by jointN: what the hierarchy and rest pose alone give.
absl::StatusOr<Skeleton> Renamed(const Skeleton& skeleton) {
  std::vector<Joint> joints = skeleton.joints();
  for (size_t j = 0; j < joints.size(); ++j) joints[j].name = absl::StrCat("joint", j + 1);
  return Skeleton::Create(std::move(joints));
}

TEST(HumanoidMap, RealSkeletonsWithoutNamesMapFromTheirShapeOrSayWhatIsMissing) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  // CMU's two conversions and the Z-up retarget are T-poses facing along their toes: the
  // shape alone finds every required slot where the names put them.
  for (const char* file :
       {"cmu/01_01_3dsmax.bvh", "cmu/01_01_motionbuilder.bvh", "other-skeletons/cmu1006_ROM.bvh"}) {
    SCOPED_TRACE(file);
    const absl::StatusOr<BvhReadResult> read = ReadBvhFile((mocap / file).string());
    ASSERT_TRUE(read.ok()) << read.status();
    const absl::StatusOr<Skeleton> renamed = Renamed(read->clip.skeleton());
    ASSERT_TRUE(renamed.ok()) << renamed.status();
    const absl::StatusOr<HumanoidMap> named = MapHumanoid(read->clip.skeleton());
    const absl::StatusOr<HumanoidMap> unnamed = MapHumanoid(*renamed);
    ASSERT_TRUE(named.ok() && unnamed.ok());
    EXPECT_TRUE(unnamed->complete()) << MissingText(*unnamed);
    for (const Slot slot : AllHumanoidSlots()) {
      if (!IsRequiredSlot(slot)) continue;
      EXPECT_EQ(unnamed->joint(slot), named->joint(slot)) << HumanoidSlotName(slot);
    }
  }
  // Bandai's rest pose lays every bone along its parent's x axis: no left or right to read from
  // it, so without names its limbs are missing, and said to be.
  const absl::StatusOr<BvhReadResult> bandai =
      ReadBvhFile((mocap / "bandai1/dataset-1_bow_active_001.bvh").string());
  ASSERT_TRUE(bandai.ok()) << bandai.status();
  const absl::StatusOr<Skeleton> renamed = Renamed(bandai->clip.skeleton());
  ASSERT_TRUE(renamed.ok()) << renamed.status();
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(*renamed);
  ASSERT_TRUE(map.ok()) << map.status();
  for (const Slot slot : AllHumanoidSlots()) {
    if (map->joint(slot) >= 0)
      std::cerr << HumanoidSlotName(slot) << " "
                << bandai->clip.skeleton().joint(map->joint(slot)).name << "\n";
  }
  EXPECT_EQ(MissingText(*map),
            "LeftUpperArm,LeftLowerArm,LeftHand,RightUpperArm,RightLowerArm,RightHand,"
            "LeftUpperLeg,LeftLowerLeg,LeftFoot,RightUpperLeg,RightLowerLeg,RightFoot");
  const std::map<std::string, std::string> torso = {
      {"Hips", "joint2"}, {"Spine", "joint3"}, {"Neck", "joint5"}, {"Head", "joint6"}};
  EXPECT_EQ(SlotNames(*renamed, *map), torso);
}

TEST(HumanoidMap, AssimpBoxingRigMaps) {
  const std::optional<std::filesystem::path> assimp = testing::AssimpBvhDir();
  if (!assimp) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  const absl::StatusOr<BvhReadResult> read = ReadBvhFile((*assimp / "Boxing_Toes.bvh").string());
  ASSERT_TRUE(read.ok()) << read.status();
  ExpectMapsTo(
      read->clip.skeleton(),
      Expected(Rig("", {"Hips", "Ab", "Chest", "Neck", "Head"}, "Left", "Right",
                   {"Collar", "Shoulder", "Elbow", "Wrist", "Hip", "Knee", "Ankle", "Toes"})));
}

}  // namespace
}  // namespace motiondb
