// The binary form of a MotionSpace, for storage and `.mcs` files.
//
// Layout, every number little-endian, doubles as IEEE-754 bit patterns:
//   "MDBSPACE"          8 bytes of magic
//   version             u32, kSpaceFormatVersion
//   payload size        u64
//   payload             the SpaceData fields (see space_serialization.cc)
//   checksum            u32, CRC-32 (IEEE) of every byte before it
// A reader rejects a wrong magic, an unknown version, a bad checksum, a truncated or overlong
// input and any payload that does not make a consistent space.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_SPACE_SPACE_SERIALIZATION_H_
#define MOTIONDB_CORE_SPACE_SPACE_SERIALIZATION_H_

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/space/motion_space.h"

namespace motiondb {

// 2 added the root velocity (flag and weight after the metric); 1 is read as without it. 3 added
// the search transform (a learned metric, after the training ranges); 1 and 2 are read as without,
// and a space without one is still written as 2, so that earlier builds read it. 4 added the
// representation (after the root velocity); 1-3 are read as joint rotations, and only a
// canonical-bones space is written as 4.
inline constexpr uint32_t kSpaceFormatVersion = 4;

std::string SerializeSpace(const MotionSpace& space);
// Errors are DATA_LOSS for damaged bytes (magic, checksum, truncation) and INVALID_ARGUMENT for
// a version this build does not read or contents that do not make a space.
absl::StatusOr<MotionSpace> ParseSpace(absl::string_view bytes);

// Writes through a temporary file renamed into place, so a reader never sees half a space.
absl::Status WriteSpaceFile(const std::string& path, const MotionSpace& space);
// Errors are prefixed with the path; NOT_FOUND when it cannot be opened.
absl::StatusOr<MotionSpace> ReadSpaceFile(const std::string& path);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_SPACE_SERIALIZATION_H_
