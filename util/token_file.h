// Bearer tokens kept in files (--auth-token-file, --token-file, secrets mounted in containers).
#ifndef MOTIONDB_UTIL_TOKEN_FILE_H_
#define MOTIONDB_UTIL_TOKEN_FILE_H_

#include <string>

#include "absl/status/statusor.h"

namespace motiondb {

// The file's contents without surrounding whitespace. INVALID_ARGUMENT naming the path when
// the token is empty or not printable ASCII without spaces (it travels in an HTTP/2 header
// value); the file's read errors otherwise. Files over 1 MiB are refused as a wrong path.
absl::StatusOr<std::string> ReadTokenFile(const std::string& path);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_TOKEN_FILE_H_
