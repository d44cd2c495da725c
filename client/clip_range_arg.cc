#include "client/clip_range_arg.h"

#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace motiondb::cli {

absl::StatusOr<v1::ClipRange> ParseClipRange(const std::string& spec) {
  v1::ClipRange range;
  const std::vector<std::string> parts = absl::StrSplit(spec, ':');
  int64_t id = 0;
  if (parts.size() > 2 || !absl::SimpleAtoi(parts[0], &id) || id < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("expected CLIP_ID, CLIP_ID:FROM-TO or CLIP_ID:FRAME, got '", spec, "'"));
  }
  range.set_clip_id(id);
  if (parts.size() == 2) {
    const std::vector<std::string> bounds = absl::StrSplit(parts[1], '-');
    int first = 0, last = 0;
    if (bounds.size() > 2 || !absl::SimpleAtoi(bounds[0], &first) ||
        !absl::SimpleAtoi(bounds.back(), &last)) {
      return absl::InvalidArgumentError(
          absl::StrCat("expected CLIP_ID:FROM-TO or CLIP_ID:FRAME, got '", spec, "'"));
    }
    range.set_first_frame(first);
    range.set_last_frame(last);
  }
  return range;
}

CLI::Validator ClipRangeCheck() {
  return CLI::Validator(
      [](const std::string& spec) { return std::string(ParseClipRange(spec).status().message()); },
      "");
}

}  // namespace motiondb::cli
