#include "core/motion/skeleton_coding.h"

#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {

void WriteSkeleton(const Skeleton& skeleton, ByteWriter& out) {
  out.U32(skeleton.joint_count());
  for (const Joint& joint : skeleton.joints()) {
    out.Str(joint.name);
    out.I32(joint.parent);
    out.F64s(joint.offset.data(), 3);
    out.U8(static_cast<uint8_t>(joint.channels.size()));
    for (const Channel channel : joint.channels) out.U8(static_cast<uint8_t>(channel));
    out.U8(joint.end_site ? 1 : 0);
    if (joint.end_site) out.F64s(joint.end_site->data(), 3);
  }
}

absl::StatusOr<std::shared_ptr<const Skeleton>> ReadSkeleton(ByteReader& in) {
  // A joint takes at least a name length, a parent, an offset and two counts.
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t joints, in.Count("joint count", 4 + 4 + 24 + 2));
  std::vector<Joint> parsed(joints);
  for (Joint& joint : parsed) {
    MOTIONDB_ASSIGN_OR_RETURN(joint.name, in.Str("joint name"));
    MOTIONDB_ASSIGN_OR_RETURN(joint.parent, in.I32("joint parent"));
    MOTIONDB_RETURN_IF_ERROR(in.F64s("joint offset", joint.offset.data(), 3));
    MOTIONDB_ASSIGN_OR_RETURN(const uint8_t channels, in.U8("channel count"));
    for (uint8_t c = 0; c < channels; ++c) {
      MOTIONDB_ASSIGN_OR_RETURN(const uint8_t channel, in.U8("channel"));
      if (channel > static_cast<uint8_t>(Channel::kZrotation)) {
        return absl::DataLossError(
            absl::StrCat("joint '", joint.name, "' has unknown channel ", channel));
      }
      joint.channels.push_back(static_cast<Channel>(channel));
    }
    MOTIONDB_ASSIGN_OR_RETURN(const uint8_t has_end_site, in.U8("End Site flag"));
    if (has_end_site != 0) {
      MOTIONDB_RETURN_IF_ERROR(in.F64s("End Site", joint.end_site.emplace().data(), 3));
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(Skeleton skeleton, Skeleton::Create(std::move(parsed)));
  return std::make_shared<const Skeleton>(std::move(skeleton));
}

}  // namespace motiondb
