// CRC-32 (IEEE 802.3, reflected), the checksum of our files.
#ifndef MOTIONDB_UTIL_CRC32_H_
#define MOTIONDB_UTIL_CRC32_H_

#include <cstdint>

#include "absl/strings/string_view.h"

namespace motiondb {

// zlib's crc32 of `bytes`.
uint32_t Crc32(absl::string_view bytes);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_CRC32_H_
