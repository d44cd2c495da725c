// The longest text a stored record holds, as the Database checks it on the way in: what the
// server bounds its answers by before it reads them.
#ifndef MOTIONDB_STORAGE_RECORD_LIMITS_H_
#define MOTIONDB_STORAGE_RECORD_LIMITS_H_

#include <cstddef>

namespace motiondb::storage {

inline constexpr size_t kMaxNameBytes = 512;  // clip, source file and space names
inline constexpr size_t kMaxTagBytes = 128;
inline constexpr size_t kMaxTags = 64;  // a clip's

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_RECORD_LIMITS_H_
