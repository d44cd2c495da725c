#include "core/motion/humanoid_map.h"

#include <algorithm>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/motion/internal/joint_name_reading.h"

namespace motiondb {
namespace {

using Slot = HumanoidSlot;

constexpr std::array<absl::string_view, kHumanoidSlotCount> kSlotNames = {
    "Hips",          "Spine",         "Chest",         "Neck",          "Head",
    "LeftShoulder",  "LeftUpperArm",  "LeftLowerArm",  "LeftHand",      "RightShoulder",
    "RightUpperArm", "RightLowerArm", "RightHand",     "LeftUpperLeg",  "LeftLowerLeg",
    "LeftFoot",      "LeftToes",      "RightUpperLeg", "RightLowerLeg", "RightFoot",
    "RightToes"};

// A limb's slots from the body outwards: an arm's first slot (the shoulder) and a leg's last
// (the toes) are optional.
struct Limb {
  std::array<Slot, 4> slots;
  std::array<BodyPart, 4> parts;
  BodySide side;
  bool arm;
};

constexpr std::array<BodyPart, 4> kArmParts = {BodyPart::kShoulder, BodyPart::kUpperArm,
                                               BodyPart::kLowerArm, BodyPart::kHand};
constexpr std::array<BodyPart, 4> kLegParts = {BodyPart::kUpperLeg, BodyPart::kLowerLeg,
                                               BodyPart::kFoot, BodyPart::kToes};
constexpr std::array<Limb, 4> kLimbs = {{
    {{Slot::kLeftUpperLeg, Slot::kLeftLowerLeg, Slot::kLeftFoot, Slot::kLeftToes},
     kLegParts,
     BodySide::kLeft,
     false},
    {{Slot::kRightUpperLeg, Slot::kRightLowerLeg, Slot::kRightFoot, Slot::kRightToes},
     kLegParts,
     BodySide::kRight,
     false},
    {{Slot::kLeftShoulder, Slot::kLeftUpperArm, Slot::kLeftLowerArm, Slot::kLeftHand},
     kArmParts,
     BodySide::kLeft,
     true},
    {{Slot::kRightShoulder, Slot::kRightUpperArm, Slot::kRightLowerArm, Slot::kRightHand},
     kArmParts,
     BodySide::kRight,
     true},
}};

// Name candidates per limb slot are few on any real rig; the bound keeps the chain search (all
// combinations of a limb's four slots) small whatever the names.
constexpr int kMaxCandidatesPerSlot = 6;

// A chain's quality: required slots filled, then slots whose joint's name says so, then the
// fewest joints skipped between consecutive slots.
using ChainScore = std::tuple<int, int, int>;

class Mapper {
 public:
  explicit Mapper(const Skeleton& skeleton) : skeleton_(skeleton), count_(skeleton.joint_count()) {
    readings_.reserve(count_);
    depth_.assign(count_, 0);
    height_.assign(count_, 1);
    size_.assign(count_, 1);
    rest_.assign(count_, Eigen::Vector3d::Zero());
    rest_sum_.assign(count_, Eigen::Vector3d::Zero());
    named_below_.assign(count_, {false, false});
    for (int j = 0; j < count_; ++j) {
      readings_.push_back(ReadJointName(skeleton.joint(j).name));
      const int parent = skeleton.joint(j).parent;
      if (parent >= 0) {
        depth_[j] = depth_[parent] + 1;
        rest_[j] = rest_[parent] + skeleton.joint(j).offset;
      }
    }
    // Parents precede children: one backwards pass sums the subtrees.
    for (int j = count_ - 1; j >= 0; --j) {
      rest_sum_[j] += rest_[j];
      const BodySide side = readings_[j].side;
      if (side != BodySide::kNone) named_below_[j][side == BodySide::kLeft ? 0 : 1] = true;
      const int parent = skeleton.joint(j).parent;
      if (parent < 0) continue;
      height_[parent] = std::max(height_[parent], height_[j] + 1);
      size_[parent] += size_[j];
      rest_sum_[parent] += rest_sum_[j];
      for (int s = 0; s < 2; ++s)
        named_below_[parent][s] = named_below_[parent][s] || named_below_[j][s];
    }
    map_.joints.fill(-1);
    owner_.assign(count_, false);
  }

  absl::Status Pin(const std::vector<SlotOverride>& overrides) {
    for (size_t i = 0; i < overrides.size(); ++i) {
      const SlotOverride& pin = overrides[i];
      const std::string what = absl::StrCat("overrides[", i, "] (", HumanoidSlotName(pin.slot), "=",
                                            pin.joint.substr(0, 128), ")");
      const int joint = skeleton_.FindJoint(pin.joint);
      if (joint < 0) {
        return absl::InvalidArgumentError(absl::StrCat(what, ": the skeleton has no joint named '",
                                                       pin.joint.substr(0, 128), "'"));
      }
      if (Get(pin.slot) >= 0) {
        return absl::InvalidArgumentError(absl::StrCat(what, ": the slot is given twice"));
      }
      if (owner_[joint]) {
        return absl::InvalidArgumentError(absl::StrCat(what, ": the joint is given to two slots"));
      }
      Set(pin.slot, joint);
    }
    return absl::OkStatus();
  }

  HumanoidMap Map() {
    FindHips();
    if (Get(Slot::kHips) >= 0) {
      FindHeadByName();
      for (const Limb& limb : kLimbs) MapLimbByName(limb);
      MapLimbsByShape();
      MapTorso();
    }
    PairMirrors();
    for (const Slot slot : AllHumanoidSlots()) {
      if (IsRequiredSlot(slot) && Get(slot) < 0) map_.missing.push_back(slot);
    }
    return std::move(map_);
  }

 private:
  int Get(Slot slot) const { return map_.joints[static_cast<int>(slot)]; }
  void Set(Slot slot, int joint) {
    map_.joints[static_cast<int>(slot)] = joint;
    owner_[joint] = true;
  }
  int Parent(int joint) const { return skeleton_.joint(joint).parent; }

  bool IsAncestor(int ancestor, int joint) const {
    for (int j = joint; j >= 0; j = Parent(j)) {
      if (j == ancestor) return true;
    }
    return false;
  }
  bool IsStrictAncestor(int ancestor, int joint) const {
    return ancestor != joint && IsAncestor(ancestor, joint);
  }

  // The child a chain goes on through: the one with the tallest subtree, the first of equals.
  int ChainChild(int joint) const {
    int best = -1;
    for (const int child : skeleton_.Children(joint)) {
      if (best < 0 || height_[child] > height_[best]) best = child;
    }
    return best;
  }

  // Named, or else the first joint from the root where three tall subtrees meet (two legs and
  // the torso).
  void FindHips() {
    if (Get(Slot::kHips) >= 0) return;
    int named = -1;
    for (int j = 0; j < count_; ++j) {
      if (readings_[j].part == BodyPart::kHips && !owner_[j] &&
          (named < 0 || depth_[j] < depth_[named])) {
        named = j;
      }
    }
    if (named >= 0) {
      Set(Slot::kHips, named);
      return;
    }
    for (int j = 0; j < count_; ++j) {
      int tall = 0;
      for (const int child : skeleton_.Children(j)) tall += height_[child] >= 3 ? 1 : 0;
      if (tall >= 3 && !owner_[j]) {
        Set(Slot::kHips, j);
        return;
      }
    }
  }

  // A limb's slots filled from `chain` (a joint or -1 for each): a slot between two chosen
  // takes the ancestors of the later one, a slot after the last chosen the chain's next joint,
  // the slot before the first chosen its parent when that may be a limb's joint. The
  // hierarchy thus fills what names leave open, and a chain whose names skip a slot that no
  // joint can fill scores lower. Returns the filled chain.
  std::array<int, 4> FillChain(std::array<int, 4> chain) const {
    const auto usable = [&](int joint) { return joint >= 0 && !owner_[joint]; };
    int last = -1;
    for (int i = 0; i < 4; ++i) {
      if (chain[i] < 0) continue;
      int ancestor = Parent(chain[i]);
      for (int k = i - 1; k > last && ancestor >= 0; --k) {
        if (last >= 0 && !IsStrictAncestor(chain[last], ancestor)) break;
        if (ancestor == Get(Slot::kHips) || !usable(ancestor)) break;
        if (last < 0 && !IsLimbJoint(ancestor)) break;
        chain[k] = ancestor;
        ancestor = Parent(ancestor);
      }
      last = i;
    }
    for (int i = last + 1; last >= 0 && i < 4; ++i) {
      const int next = ChainChild(chain[i - 1]);
      if (!usable(next)) break;
      chain[i] = next;
    }
    return chain;
  }

  // A joint that may belong to a limb: below the hips, not on the way to the head, and not
  // above joints named for both sides (the chest). A side's name does not bar it: an override
  // may give a limb the other side's chain (a rig whose names have the sides swapped).
  bool IsLimbJoint(int joint) const {
    if (!IsStrictAncestor(Get(Slot::kHips), joint)) return false;
    if (head_ >= 0 && IsAncestor(joint, head_)) return false;
    return !(named_below_[joint][0] && named_below_[joint][1]);
  }

  ChainScore Score(const Limb& limb, const std::array<int, 4>& named,
                   const std::array<int, 4>& filled) const {
    int required = 0, by_name = 0, skipped = 0, previous = -1;
    for (int i = 0; i < 4; ++i) {
      if (filled[i] < 0) continue;
      required += IsRequiredSlot(limb.slots[i]) ? 1 : 0;
      by_name += named[i] >= 0 ? 1 : 0;
      if (previous >= 0) skipped += depth_[filled[i]] - depth_[previous] - 1;
      previous = filled[i];
    }
    return {required, by_name, -skipped};
  }

  // Tries every combination of the limb's name candidates (each slot: a joint named for it,
  // or none) whose joints run down one chain, fills each, and keeps the best.
  void MapLimbByName(const Limb& limb) {
    std::array<std::vector<int>, 4> candidates;
    for (int i = 0; i < 4; ++i) {
      if (Get(limb.slots[i]) >= 0) {
        candidates[i] = {Get(limb.slots[i])};
        continue;
      }
      for (int j = 0; j < count_ && candidates[i].size() < kMaxCandidatesPerSlot; ++j) {
        if (!owner_[j] && readings_[j].part == limb.parts[i] && readings_[j].side == limb.side &&
            IsStrictAncestor(Get(Slot::kHips), j)) {
          candidates[i].push_back(j);
        }
      }
      candidates[i].push_back(-1);
    }
    std::array<int, 4> best{-1, -1, -1, -1};
    ChainScore best_score{0, 0, 0};
    std::array<int, 4> named{};
    const auto visit = [&](auto&& self, int slot, int previous) -> void {
      if (slot == 4) {
        const std::array<int, 4> filled = FillChain(named);
        const ChainScore score = Score(limb, named, filled);
        if (score > best_score) {
          best_score = score;
          best = filled;
        }
        return;
      }
      for (const int joint : candidates[slot]) {
        if (joint >= 0 && previous >= 0 && !IsStrictAncestor(previous, joint)) continue;
        named[slot] = joint;
        self(self, slot + 1, joint >= 0 ? joint : previous);
      }
    };
    visit(visit, 0, -1);
    // Only a chain that some name started: a limb no name mentions is left to the shape.
    if (std::get<1>(best_score) == 0) return;
    for (int i = 0; i < 4; ++i) {
      if (best[i] >= 0 && Get(limb.slots[i]) < 0) Set(limb.slots[i], best[i]);
    }
  }

  void FindHeadByName() {
    head_ = Get(Slot::kHead);
    for (int j = 0; j < count_ && head_ < 0; ++j) {
      if (readings_[j].part == BodyPart::kHead && !owner_[j] &&
          IsStrictAncestor(Get(Slot::kHips), j)) {
        head_ = j;
      }
    }
  }

  // The hips' child that carries the torso: the head's side, or else the largest subtree.
  int TorsoChild() const {
    int best = -1;
    for (const int child : skeleton_.Children(Get(Slot::kHips))) {
      if (head_ >= 0 && IsAncestor(child, head_)) return child;
      if (best < 0 || size_[child] > size_[best]) best = child;
    }
    return best;
  }

  // Where the arms leave the torso: the first joint down the torso's chain with three children
  // or more (two arms and the neck).
  int ArmBranch() const {
    for (int j = TorsoChild(); j >= 0; j = ChainChild(j)) {
      if (skeleton_.Children(j).size() >= 3) return j;
    }
    return -1;
  }

  // A limb from its root down its chain. The upper bone starts at the joint after the root
  // (the root then a shoulder, or a hip helper such as CMU's LHipJoint for a leg) when the root
  // sits where its parent does (CMU's LeftCollar and LHipJoint: a bone's length says nothing
  // there, CMU's collar bone being longer than its forearm), or when the two bones after the
  // root are the longer pair; else at the root.
  std::array<int, 4> ShapeChain(int root, bool arm) const {
    std::vector<int> chain;
    for (int j = root; j >= 0 && chain.size() < 6; j = ChainChild(j)) chain.push_back(j);
    const auto bone = [&](size_t i) {
      return i + 1 < chain.size() ? skeleton_.joint(chain[i + 1]).offset.norm() : 0.0;
    };
    const bool at_parent = skeleton_.joint(root).offset.norm() < 1e-3 * (bone(0) + bone(1));
    const size_t upper = at_parent || bone(1) + bone(2) > bone(0) + bone(1) ? 1 : 0;
    const auto at = [&](size_t i) { return i < chain.size() ? chain[i] : -1; };
    if (arm) return {upper == 1 ? at(0) : -1, at(upper), at(upper + 1), at(upper + 2)};
    return {at(upper), at(upper + 1), at(upper + 2), at(upper + 3)};
  }

  // The two roots among `roots` farthest apart across the body, left first, by the rest
  // positions of their subtrees.
  std::pair<int, int> SplitSides(const std::vector<int>& roots) const {
    if (!left_) return {-1, -1};
    int left = -1, right = -1;
    double most = 0, least = 0;
    for (const int root : roots) {
      const double across = Across(rest_sum_[root] / size_[root]);
      if (left < 0 || across > most) left = root, most = across;
      if (right < 0 || across < least) right = root, least = across;
    }
    if (left == right) return {-1, -1};
    return {left, right};
  }

  // How far left of the hips a rest position lies; only with a left direction.
  double Across(const Eigen::Vector3d& position) const {
    return (position - rest_[Get(Slot::kHips)]).dot(*left_);
  }

  // The body's up and left directions (see MapHumanoid): up from the hips to the head (or the
  // arms' branch), forward from each foot to its toe (or end site). No left when the feet give
  // no forward direction across the up one and +X lies along it too: Bandai's rest pose lays
  // every bone along its parent's x axis, the toes cancelling out, and its sides cannot be read.
  void FindUpAndLeft(const std::vector<std::array<int, 4>>& legs, int top) {
    const Eigen::Vector3d up =
        top >= 0 ? Eigen::Vector3d(rest_[top] - rest_[Get(Slot::kHips)]) : Eigen::Vector3d::UnitY();
    up_ = up.norm() > 0 ? up.normalized() : Eigen::Vector3d::UnitY();
    Eigen::Vector3d forward = Eigen::Vector3d::Zero();
    double feet = 0;
    for (const std::array<int, 4>& leg : legs) {
      if (leg[2] < 0) continue;
      const Joint& foot = skeleton_.joint(leg[2]);
      const std::optional<Eigen::Vector3d> toe =
          leg[3] >= 0 ? std::optional<Eigen::Vector3d>(skeleton_.joint(leg[3]).offset)
                      : foot.end_site;
      if (!toe) continue;
      forward += *toe;
      feet += toe->norm();
    }
    forward -= forward.dot(up_) * up_;
    const Eigen::Vector3d x_across = Eigen::Vector3d::UnitX() - up_.x() * up_;
    if (feet > 0 && forward.norm() > 0.1 * feet) {
      left_ = up_.cross(forward).normalized();
    } else if (x_across.norm() > 0.5) {
      left_ = x_across.normalized();
    } else {
      left_.reset();
    }
  }

  // The limbs no name mapped, from the shape: the legs are the hips' other tall subtrees, the
  // arms the outermost children of the arms' branch; sides from the rest positions.
  void MapLimbsByShape() {
    std::vector<int> leg_roots;
    const int torso = TorsoChild();
    for (const int child : skeleton_.Children(Get(Slot::kHips))) {
      if (child != torso && height_[child] >= 3) leg_roots.push_back(child);
    }
    std::vector<std::array<int, 4>> legs;
    for (const int root : leg_roots) legs.push_back(ShapeChain(root, /*arm=*/false));
    const int branch = ArmBranch();
    FindUpAndLeft(legs, head_ >= 0 ? head_ : branch);
    const auto [left_leg, right_leg] = SplitSides(leg_roots);
    std::vector<int> arm_roots;
    if (branch >= 0) {
      for (const int child : skeleton_.Children(branch)) {
        if (head_ < 0 || !IsAncestor(child, head_)) arm_roots.push_back(child);
      }
    }
    const auto [left_arm, right_arm] = SplitSides(arm_roots);
    const std::array<int, 4> roots = {left_leg, right_leg, left_arm, right_arm};
    for (size_t i = 0; i < kLimbs.size(); ++i) {
      const Limb& limb = kLimbs[i];
      const bool unmapped = std::none_of(limb.slots.begin(), limb.slots.end(),
                                         [&](Slot slot) { return Get(slot) >= 0; });
      if (!unmapped || roots[i] < 0) continue;
      const std::array<int, 4> chain = ShapeChain(roots[i], limb.arm);
      for (int k = 0; k < 4; ++k) {
        if (chain[k] >= 0 && !owner_[chain[k]]) Set(limb.slots[k], chain[k]);
      }
    }
  }

  // The first joint of `path` (hips to head) after `after` named as `part`; -1 when none.
  int OnPath(const std::vector<int>& path, size_t after, BodyPart part) const {
    for (size_t i = after + 1; i + 1 < path.size(); ++i) {
      if (readings_[path[i]].part == part && !owner_[path[i]]) return static_cast<int>(i);
    }
    return -1;
  }

  // Spine, chest and neck on the path from the hips to the head. The chest is where the arms
  // branch off when that is on the path, the same place on every rig however many spine joints
  // it has (CMU's Chest2 and Spine1 in its two conversions), else a joint named so.
  void MapTorso() {
    if (Get(Slot::kHead) < 0) {
      int head = head_;
      if (head < 0) {
        // The end of the chain the arms' branch continues in: its child whose subtree lies
        // most nearly straight up from it.
        const int branch = ArmBranch();
        double most_up = -2;
        for (const int child : branch >= 0 ? skeleton_.Children(branch) : std::vector<int>()) {
          const Eigen::Vector3d away = rest_sum_[child] / size_[child] - rest_[branch];
          const double up = away.norm() > 0 ? away.normalized().dot(up_) : -1;
          if (!owner_[child] && up > most_up) head = child, most_up = up;
        }
        while (head >= 0 && ChainChild(head) >= 0) head = ChainChild(head);
      }
      if (head >= 0 && !owner_[head]) Set(Slot::kHead, head);
    }
    const int head = Get(Slot::kHead);
    if (head < 0 || !IsStrictAncestor(Get(Slot::kHips), head)) return;
    std::vector<int> path;
    for (int j = head; j != Get(Slot::kHips); j = Parent(j)) path.push_back(j);
    path.push_back(Get(Slot::kHips));
    std::reverse(path.begin(), path.end());
    const auto index_of = [&](int joint) {
      return static_cast<int>(std::find(path.begin(), path.end(), joint) - path.begin());
    };
    const int last = static_cast<int>(path.size()) - 1;
    int spine =
        Get(Slot::kSpine) >= 0 ? index_of(Get(Slot::kSpine)) : OnPath(path, 0, BodyPart::kSpine);
    if (spine < 0 && last > 1 && !owner_[path[1]]) spine = 1;
    if (spine < 0 || spine >= last) return;
    if (Get(Slot::kSpine) < 0) Set(Slot::kSpine, path[spine]);
    int chest = Get(Slot::kChest) >= 0 ? index_of(Get(Slot::kChest)) : -1;
    if (chest < 0) {
      const int branch = ArmsMeet();
      const int at = branch >= 0 ? index_of(branch) : last;
      chest = at > spine && at < last ? at : OnPath(path, spine, BodyPart::kChest);
      if (chest >= 0 && !owner_[path[chest]]) Set(Slot::kChest, path[chest]);
    }
    const int above = std::max(spine, chest);
    if (Get(Slot::kNeck) >= 0 || above >= last - 1) return;
    int neck = OnPath(path, above, BodyPart::kNeck);
    if (neck < 0 && !owner_[path[last - 1]]) neck = last - 1;
    if (neck >= 0) Set(Slot::kNeck, path[neck]);
  }

  // The lowest joint above both upper arms (or shoulders); -1 unless both sides have one.
  int ArmsMeet() const {
    const auto arm_top = [&](Slot shoulder, Slot upper) {
      return Get(shoulder) >= 0 ? Get(shoulder) : Get(upper);
    };
    const int left = arm_top(Slot::kLeftShoulder, Slot::kLeftUpperArm);
    const int right = arm_top(Slot::kRightShoulder, Slot::kRightUpperArm);
    if (left < 0 || right < 0) return -1;
    for (int j = Parent(left); j >= 0; j = Parent(j)) {
      if (IsAncestor(j, right)) return j;
    }
    return -1;
  }

  // The slots' pairs, then joints whose names differ by the side alone, then, from every pair,
  // the parents (up to where the sides meet) and the children (in order, when both have as many
  // unpaired children) of the two.
  void PairMirrors() {
    std::vector<int> mirror(count_, -1);
    std::vector<std::pair<int, int>> pending;
    const auto pair = [&](int left, int right) {
      if (left < 0 || right < 0 || left == right || mirror[left] >= 0 || mirror[right] >= 0) {
        return;
      }
      mirror[left] = right;
      mirror[right] = left;
      map_.mirror_pairs.emplace_back(left, right);
      pending.emplace_back(left, right);
    };
    for (int i = 0; i < 4; ++i) {
      pair(Get(kLimbs[0].slots[i]), Get(kLimbs[1].slots[i]));
      pair(Get(kLimbs[2].slots[i]), Get(kLimbs[3].slots[i]));
    }
    absl::flat_hash_map<std::string, int> right_by_key;
    for (int j = 0; j < count_; ++j) {
      if (readings_[j].side == BodySide::kRight) right_by_key.emplace(readings_[j].mirror_key, j);
    }
    for (int j = 0; j < count_; ++j) {
      if (readings_[j].side != BodySide::kLeft) continue;
      const auto right = right_by_key.find(readings_[j].mirror_key);
      if (right != right_by_key.end()) pair(j, right->second);
    }
    while (!pending.empty()) {
      const auto [left, right] = pending.back();
      pending.pop_back();
      const int left_parent = Parent(left), right_parent = Parent(right);
      if (left_parent >= 0 && right_parent >= 0 && left_parent != right_parent &&
          !IsAncestor(left_parent, right) && !IsAncestor(right_parent, left)) {
        pair(left_parent, right_parent);
      }
      const std::vector<int> left_children = skeleton_.Children(left);
      const std::vector<int> right_children = skeleton_.Children(right);
      const auto unpaired = [&](int joint) { return mirror[joint] < 0; };
      if (left_children.size() == right_children.size() &&
          std::all_of(left_children.begin(), left_children.end(), unpaired) &&
          std::all_of(right_children.begin(), right_children.end(), unpaired)) {
        for (size_t c = 0; c < left_children.size(); ++c) pair(left_children[c], right_children[c]);
      }
    }
    std::sort(map_.mirror_pairs.begin(), map_.mirror_pairs.end());
  }

  const Skeleton& skeleton_;
  const int count_;
  std::vector<JointNameReading> readings_;
  std::vector<int> depth_;   // joints from the root
  std::vector<int> height_;  // joints on the longest path down from the joint, itself included
  std::vector<int> size_;    // joints in the subtree
  std::vector<Eigen::Vector3d> rest_;      // rest positions: the offsets summed from the root
  std::vector<Eigen::Vector3d> rest_sum_;  // of the subtree's rest positions
  std::vector<std::array<bool, 2>> named_below_;  // a joint named left, right in the subtree
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitY();
  std::optional<Eigen::Vector3d> left_;  // none when the rest pose shows no left
  int head_ = -1;                        // the head, once a name or an override found it
  std::vector<bool> owner_;              // whether the joint plays a slot
  HumanoidMap map_;
};

}  // namespace

absl::string_view HumanoidSlotName(HumanoidSlot slot) { return kSlotNames[static_cast<int>(slot)]; }

std::optional<HumanoidSlot> ParseHumanoidSlot(absl::string_view name) {
  for (int i = 0; i < kHumanoidSlotCount; ++i) {
    if (absl::EqualsIgnoreCase(kSlotNames[i], name)) return static_cast<HumanoidSlot>(i);
  }
  return std::nullopt;
}

bool IsRequiredSlot(HumanoidSlot slot) {
  switch (slot) {
    case Slot::kChest:
    case Slot::kNeck:
    case Slot::kLeftShoulder:
    case Slot::kRightShoulder:
    case Slot::kLeftToes:
    case Slot::kRightToes:
      return false;
    default:
      return true;
  }
}

const std::array<HumanoidSlot, kHumanoidSlotCount>& AllHumanoidSlots() {
  static const std::array<HumanoidSlot, kHumanoidSlotCount> slots = [] {
    std::array<HumanoidSlot, kHumanoidSlotCount> all{};
    for (int i = 0; i < kHumanoidSlotCount; ++i) all[i] = static_cast<HumanoidSlot>(i);
    return all;
  }();
  return slots;
}

absl::StatusOr<HumanoidMap> MapHumanoid(const Skeleton& skeleton,
                                        const std::vector<SlotOverride>& overrides) {
  Mapper mapper(skeleton);
  if (absl::Status pinned = mapper.Pin(overrides); !pinned.ok()) return pinned;
  return mapper.Map();
}

}  // namespace motiondb
