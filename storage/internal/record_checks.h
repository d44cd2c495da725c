// The limits on what callers ask the Database to store, checked before any SQL runs.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_STORAGE_INTERNAL_RECORD_CHECKS_H_
#define MOTIONDB_STORAGE_INTERNAL_RECORD_CHECKS_H_

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/matrix.h"

namespace motiondb::storage {

inline constexpr size_t kMaxNameBytes = 512;  // clip, source file and space names
inline constexpr size_t kMaxTagBytes = 128;
inline constexpr size_t kMaxTags = 64;  // a clip's

// INVALID_ARGUMENT naming `what` for an empty `name` (unless `may_be_empty`) or one longer than
// `max_bytes`.
absl::Status CheckName(absl::string_view what, absl::string_view name, size_t max_bytes,
                       bool may_be_empty = false);

// Tags are a set: checked, sorted and without repeats, as ListClips and GetClip return them.
absl::StatusOr<std::vector<std::string>> CanonicalTags(std::vector<std::string> tags);

// INVALID_ARGUMENT naming `what` for a projection without columns, with more columns than
// `space_dims` (the dimensions of the stored space, when known yet), or with non-finite values.
absl::Status CheckProjection(const RowMatrixXf& coordinates, std::optional<int> space_dims,
                             absl::string_view what);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_INTERNAL_RECORD_CHECKS_H_
