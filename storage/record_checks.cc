#include "storage/internal/record_checks.h"
#include "storage/database.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "storage/database.h"
#include "util/name_text.h"
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
  return CheckNameText(what, name);
}

absl::Status CheckClipName(absl::string_view name) {
  constexpr absl::string_view kWhat = "clip name";
  MOTIONDB_RETURN_IF_ERROR(CheckName(kWhat, name, kMaxNameBytes));
  if (name.front() == '/' || name.back() == '/') {
    return absl::InvalidArgumentError(
        absl::StrCat(kWhat, " ", QuotedNameText(name),
                     " begins or ends with '/'; give a relative path such as "
                     "'session1/take_001'"));
  }
  for (const absl::string_view segment : absl::StrSplit(name, '/')) {
    if (segment.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat(kWhat, " ", QuotedNameText(name), " has an empty segment ('//')"));
    }
    if (segment == "." || segment == "..") {
      return absl::InvalidArgumentError(
          absl::StrCat(kWhat, " ", QuotedNameText(name), " has a '", segment,
                       "' segment; '/' separates folders, which are named outright"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<std::string>> CanonicalTags(std::vector<std::string> tags,
                                                       absl::string_view field) {
  if (tags.size() > kMaxTags) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": a clip has at most ", kMaxTags, " tags, got ", tags.size()));
  }
  for (size_t i = 0; i < tags.size(); ++i) {
    MOTIONDB_RETURN_IF_ERROR(CheckName(absl::StrCat(field, "[", i, "]"), tags[i], kMaxTagBytes));
  }
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

absl::StatusOr<int> CheckPageSize(int page_size) {
  if (page_size < 0 || page_size > kMaxPageSize) {
    return absl::InvalidArgumentError(absl::StrCat("page_size must be 1 to ", kMaxPageSize,
                                                   " (0 for ", kDefaultPageSize, "), got ",
                                                   page_size));
  }
  return page_size == 0 ? kDefaultPageSize : page_size;
}

absl::Status CheckLabel(const LabelRecord& label, size_t index) {
  const std::string item = absl::StrCat("labels[", index, "]");
  MOTIONDB_RETURN_IF_ERROR(
      CheckName(absl::StrCat(item, ".descriptor"), label.descriptor, kMaxDescriptorBytes));
  // Written so that NaN fails too.
  if (!(label.value >= 0 && label.value <= 1)) {
    return absl::InvalidArgumentError(
        absl::StrCat(item, ".value: ", label.value, " is outside [0, 1]"));
  }
  if (label.first_frame < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(item, ".first_frame: ", label.first_frame, " is negative"));
  }
  if (label.last_frame < label.first_frame) {
    return absl::InvalidArgumentError(absl::StrCat(item, ".last_frame: ", label.last_frame,
                                                   " is before first_frame ", label.first_frame));
  }
  if (label.origin == LabelOrigin::kManual) {
    if (label.source_label_id != 0 || label.space_id != 0 || label.score != 0 ||
        !label.job_id.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat(item, ": a manual label has no source_label_id, space_id, score or job_id"));
    }
  } else if (label.source_label_id <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(item, ".source_label_id: a propagated label names the label it came from"));
  } else if (!std::isfinite(label.score)) {
    return absl::InvalidArgumentError(
        absl::StrCat(item, ".score: ", label.score, " is not finite"));
  }
  return absl::OkStatus();
}

absl::Status CheckDescriptor(const std::string& what, const std::string& descriptor) {
  return CheckName(what, descriptor, kMaxDescriptorBytes);
}

}  // namespace motiondb::storage
