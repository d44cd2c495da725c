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
#include "storage/clip_name_check.h"
#include "storage/label_record.h"
#include "storage/record_limits.h"

namespace motiondb::storage {

// INVALID_ARGUMENT naming `what` for an empty `name` (unless `may_be_empty`), one longer than
// `max_bytes`, or one that util/name_text.h's rule refuses: not UTF-8, or holding a control,
// bidirectional control or line separator character. Names and tags are printed in listings,
// logs, terminals and spreadsheets, where such a character would hide, rewrite or reorder what
// follows it, NUL would cut the name short in C strings, and protobuf carries UTF-8 only.
absl::Status CheckName(absl::string_view what, absl::string_view name, size_t max_bytes,
                       bool may_be_empty = false);

// Tags are a set: checked, sorted and without repeats, as ListClips and GetClip return them.
// Errors name the tag as `field`[i].
absl::StatusOr<std::vector<std::string>> CanonicalTags(std::vector<std::string> tags,
                                                       absl::string_view field = "tags");

// INVALID_ARGUMENT naming `what` for a projection without columns, with more columns than
// `space_dims` (the dimensions of the stored space, when known yet), or with non-finite values.
absl::Status CheckProjection(const RowMatrixXf& coordinates, std::optional<int> space_dims,
                             absl::string_view what);

// The rows of a page that Page::page_size asks for: 0 means kDefaultPageSize; outside
// 0..kMaxPageSize is INVALID_ARGUMENT.
absl::StatusOr<int> CheckPageSize(int page_size);

// What AddLabels can check of `label`, item `index` of its batch, without the database:
// INVALID_ARGUMENT naming "labels[index].field" for a negative or reversed range, a value
// outside [0, 1] (NaN too), a descriptor that CheckName refuses (at most kMaxDescriptorBytes),
// a manual label with a source, space, score or job, or a propagated one without a source.
absl::Status CheckLabel(const LabelRecord& label, size_t index);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_INTERNAL_RECORD_CHECKS_H_
