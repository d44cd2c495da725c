// Prefixing a status's message with where it happened ("walk.bvh: line 19: expected ..."), the
// one way every layer adds context to an error it passes on.
#ifndef MOTIONDB_UTIL_STATUS_PREFIX_H_
#define MOTIONDB_UTIL_STATUS_PREFIX_H_

#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb {

// `status` with "`prefix`: " before its message; code and payloads kept, OK stays OK.
absl::Status Prefixed(absl::string_view prefix, const absl::Status& status);

// The value, or its status prefixed; reads well inside MOTIONDB_ASSIGN_OR_RETURN.
template <typename T>
absl::StatusOr<T> Prefixed(absl::string_view prefix, absl::StatusOr<T> result) {
  if (result.ok()) return result;
  return Prefixed(prefix, result.status());
}

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_STATUS_PREFIX_H_
