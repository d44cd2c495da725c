#include "storage/internal/record_checks.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb::storage {

absl::Status CheckName(absl::string_view what, absl::string_view name, size_t max_bytes,
                       bool may_be_empty) {
  if (name.empty() && !may_be_empty) {
    return absl::InvalidArgumentError(absl::StrCat(what, " must not be empty"));
  }
  if (name.size() > max_bytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, " is ", name.size(), " bytes long, at most ", max_bytes, " are allowed"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<std::string>> CanonicalTags(std::vector<std::string> tags) {
  if (tags.size() > kMaxTags) {
    return absl::InvalidArgumentError(
        absl::StrCat("a clip has at most ", kMaxTags, " tags, got ", tags.size()));
  }
  for (const std::string& tag : tags) MOTIONDB_RETURN_IF_ERROR(CheckName("tag", tag, kMaxTagBytes));
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
  return tags;
}

absl::Status CheckProjection(const RowMatrixXf& coordinates, std::optional<int> space_dims,
                             absl::string_view what) {
  if (coordinates.cols() < 1)
    return absl::InvalidArgumentError(absl::StrCat(what, " has no columns"));
  if (space_dims && coordinates.cols() > *space_dims) {
    return absl::InvalidArgumentError(absl::StrCat(what, " has ", coordinates.cols(),
                                                   " columns, more than the space's ", *space_dims,
                                                   " dimensions"));
  }
  if (!coordinates.allFinite()) {
    return absl::InvalidArgumentError(absl::StrCat(what, " contains NaN or infinite values"));
  }
  return absl::OkStatus();
}

}  // namespace motiondb::storage
