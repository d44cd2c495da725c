// Whole-file reads and atomic whole-file writes, with errors that name the path.
//
// Pure functions; thread-safe (concurrent writers of one path race on the rename, last wins).
#ifndef MOTIONDB_UTIL_FILE_IO_H_
#define MOTIONDB_UTIL_FILE_IO_H_

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb {

// The file's bytes. NOT_FOUND when it cannot be opened, RESOURCE_EXHAUSTED over `max_bytes`.
absl::StatusOr<std::string> ReadFileBytes(const std::string& path, int64_t max_bytes);

// Writes `bytes` to `path` + ".tmp", then renames it into place, so that a reader never sees a
// half-written file.
absl::Status WriteFileAtomically(const std::string& path, absl::string_view bytes);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_FILE_IO_H_
