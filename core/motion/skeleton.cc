#include "core/motion/skeleton.h"

#include <array>
#include <utility>
#include "absl/container/flat_hash_set.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace motiondb {
namespace {

constexpr std::array<absl::string_view, 6> kChannelNames = {"Xposition", "Yposition", "Zposition",
                                                            "Xrotation", "Yrotation", "Zrotation"};

bool IsRotation(Channel c) { return c >= Channel::kXrotation; }
int AxisOf(Channel c) { return static_cast<int>(c) % 3; }

}  // namespace

absl::Status ValidateJointChannels(const Joint& joint) {
  std::array<int, 2> counts = {0, 0};
  std::array<bool, 6> seen = {};
  for (Channel c : joint.channels) {
    const int index = static_cast<int>(c);
    if (seen[index]) {
      return absl::InvalidArgumentError(
          absl::StrCat("joint '", joint.name, "': channel ", ChannelName(c), " listed twice"));
    }
    seen[index] = true;
    ++counts[IsRotation(c) ? 1 : 0];
  }
  for (int kind = 0; kind < 2; ++kind) {
    if (counts[kind] != 0 && counts[kind] != 3) {
      return absl::InvalidArgumentError(absl::StrCat("joint '", joint.name, "': expected 0 or 3 ",
                                                     kind ? "rotation" : "position",
                                                     " channels, found ", counts[kind]));
    }
  }
  return absl::OkStatus();
}

absl::string_view ChannelName(Channel channel) { return kChannelNames[static_cast<int>(channel)]; }

std::optional<Channel> ParseChannel(absl::string_view name) {
  for (size_t i = 0; i < kChannelNames.size(); ++i) {
    if (kChannelNames[i] == name) return static_cast<Channel>(i);
  }
  return std::nullopt;
}

absl::StatusOr<Skeleton> Skeleton::Create(std::vector<Joint> joints) {
  if (joints.empty()) return absl::InvalidArgumentError("skeleton has no joints");
  absl::flat_hash_set<absl::string_view> names;
  for (size_t i = 0; i < joints.size(); ++i) {
    const Joint& joint = joints[i];
    if (joint.name.empty()) {
      return absl::InvalidArgumentError(absl::StrCat("joint ", i, " has an empty name"));
    }
    if (!names.insert(joint.name).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("joint name '", joint.name, "' is not unique"));
    }
    const bool is_root = i == 0;
    if (is_root ? joint.parent != -1 : (joint.parent < 0 || joint.parent >= static_cast<int>(i))) {
      return absl::InvalidArgumentError(absl::StrCat(
          "joint '", joint.name, "': parent index ", joint.parent,
          is_root ? " (the first joint must be the root)" : " must name an earlier joint"));
    }
    if (!joint.offset.allFinite() || (joint.end_site && !joint.end_site->allFinite())) {
      return absl::InvalidArgumentError(
          absl::StrCat("joint '", joint.name, "': offset not finite"));
    }
    if (absl::Status status = ValidateJointChannels(joint); !status.ok()) return status;
  }
  return Skeleton(std::move(joints));
}

Skeleton::Skeleton(std::vector<Joint> joints) : joints_(std::move(joints)) {
  rotation_order_.resize(joints_.size());
  position_slot_.assign(joints_.size(), -1);
  for (size_t i = 0; i < joints_.size(); ++i) {
    std::array<int, 3> rotation_axes{};
    int rotations = 0;
    bool has_position = false;
    for (Channel c : joints_[i].channels) {
      if (IsRotation(c)) {
        rotation_axes[rotations++] = AxisOf(c);
      } else {
        has_position = true;
      }
    }
    if (rotations == 3) rotation_order_[i] = EulerOrderFromAxes(rotation_axes);
    if (has_position) position_slot_[i] = position_joint_count_++;
    channel_count_ += static_cast<int>(joints_[i].channels.size());
  }
}

int Skeleton::FindJoint(absl::string_view name) const {
  for (size_t i = 0; i < joints_.size(); ++i) {
    if (joints_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<int> Skeleton::Children(int index) const {
  std::vector<int> children;
  for (size_t i = index + 1; i < joints_.size(); ++i) {
    if (joints_[i].parent == index) children.push_back(static_cast<int>(i));
  }
  return children;
}

bool Skeleton::SameTopology(const Skeleton& other) const {
  if (joints_.size() != other.joints_.size()) return false;
  for (size_t i = 0; i < joints_.size(); ++i) {
    if (joints_[i].name != other.joints_[i].name || joints_[i].parent != other.joints_[i].parent) {
      return false;
    }
  }
  return true;
}

}  // namespace motiondb
