// A skeleton's bytes, as space files and storage's clip layouts both hold them: u32 joint count;
// per joint: u32 name length, name, i32 parent, 3 f64 offset, u8 channel count, that many u8
// Channel values, u8 End Site flag, [3 f64 End Site] (little-endian; doubles bit for bit).
#ifndef MOTIONDB_CORE_MOTION_SKELETON_CODING_H_
#define MOTIONDB_CORE_MOTION_SKELETON_CODING_H_

#include <memory>

#include "absl/status/statusor.h"
#include "core/motion/skeleton.h"
#include "util/byte_coding.h"

namespace motiondb {

void WriteSkeleton(const Skeleton& skeleton, ByteWriter& out);

// DATA_LOSS for damaged bytes; Skeleton::Create's errors for an inconsistent hierarchy.
absl::StatusOr<std::shared_ptr<const Skeleton>> ReadSkeleton(ByteReader& in);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_SKELETON_CODING_H_
