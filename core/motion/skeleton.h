// A skeleton: the joint hierarchy of a clip, with each joint's offset and BVH channel list
// (kept so that an export reproduces the original file's hierarchy and channel orders).
//
// Immutable after Create(); thread-safe for concurrent reads.
#ifndef MOTIONDB_CORE_MOTION_SKELETON_H_
#define MOTIONDB_CORE_MOTION_SKELETON_H_

#include <optional>
#include <string>
#include <vector>
#include "absl/strings/string_view.h"

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/rotation.h"

namespace motiondb {

enum class Channel { kXposition, kYposition, kZposition, kXrotation, kYrotation, kZrotation };

// "Xposition", ..., "Zrotation".
absl::string_view ChannelName(Channel channel);
// Parses a BVH channel name (case-sensitive, as every exporter writes them), or nullopt.
std::optional<Channel> ParseChannel(absl::string_view name);

struct Joint {
  std::string name;
  int parent = -1;                                   // index of the parent joint; -1 for the root
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // from the parent, in the file's units
  std::vector<Channel> channels;                     // in file order: 0, 3 or 6 channels
  std::optional<Eigen::Vector3d> end_site;           // the End Site offset, when the file has one
};

// Checks a joint's channel list: zero or three distinct axes of each kind (position, rotation).
absl::Status ValidateJointChannels(const Joint& joint);

class Skeleton {
 public:
  // Validates the hierarchy: joint 0 is the only root, every parent precedes its children,
  // names are unique and non-empty, and each joint has zero or three distinct rotation
  // channels and zero or three distinct position channels.
  static absl::StatusOr<Skeleton> Create(std::vector<Joint> joints);

  int joint_count() const { return static_cast<int>(joints_.size()); }
  const Joint& joint(int index) const { return joints_[index]; }
  const std::vector<Joint>& joints() const { return joints_; }
  // Index of the joint called `name`, or -1.
  int FindJoint(absl::string_view name) const;
  std::vector<int> Children(int index) const;

  // Total number of channels, i.e. values per BVH frame row.
  int channel_count() const { return channel_count_; }
  bool has_rotation(int index) const { return rotation_order_[index].has_value(); }
  // The joint's Euler order; only meaningful when has_rotation(index).
  EulerOrder rotation_order(int index) const { return *rotation_order_[index]; }
  // Index of the joint among the joints with position channels (their slot in
  // Clip::positions()), or -1 when the joint has none.
  int position_slot(int index) const { return position_slot_[index]; }
  int position_joint_count() const { return position_joint_count_; }

  // True when joint names and parents are identical (offsets and channels may differ).
  bool SameTopology(const Skeleton& other) const;

 private:
  explicit Skeleton(std::vector<Joint> joints);

  std::vector<Joint> joints_;
  std::vector<std::optional<EulerOrder>> rotation_order_;
  std::vector<int> position_slot_;
  int position_joint_count_ = 0;
  int channel_count_ = 0;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_SKELETON_H_
