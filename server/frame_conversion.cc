#include "server/frame_conversion.h"

#include <algorithm>
#include <cmath>
#include <ranges>

#include "absl/strings/str_cat.h"

namespace motiondb::server {

int FrameConversion::ToOriginal(int64_t space_frame) const {
  const double original = std::round(static_cast<double>(space_frame) * fps_ / rate_);
  return static_cast<int>(std::clamp(original, 0.0, static_cast<double>(frame_count_ - 1)));
}

int64_t FrameConversion::ToSpace(int original_frame) const {
  const double space = std::round(static_cast<double>(original_frame) * rate_ / fps_);
  return static_cast<int64_t>(std::clamp(space, 0.0, static_cast<double>(space_frames_ - 1)));
}

std::pair<int64_t, int64_t> FrameConversion::ToSpace(FrameRange range) const {
  return {ToSpace(range.first), std::max(ToSpace(range.first), ToSpace(range.last))};
}

std::pair<int64_t, int64_t> FrameConversion::SpaceFramesWithin(FrameRange range) const {
  const auto frames = std::views::iota(int64_t{0}, space_frames_);
  const int64_t first =
      std::ranges::partition_point(frames, [&](int64_t s) { return ToOriginal(s) < range.first; }) -
      frames.begin();
  const int64_t after =
      std::ranges::partition_point(frames, [&](int64_t s) { return ToOriginal(s) <= range.last; }) -
      frames.begin();
  return {first, after - 1};
}

absl::StatusOr<FrameRange> ResolveFrameRange(std::optional<int> first, std::optional<int> last,
                                             int frame_count, absl::string_view field) {
  const FrameRange range{first.value_or(0), last.value_or(frame_count - 1)};
  if (range.first < 0 || range.first >= frame_count) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".first_frame ", range.first, " is outside the clip's frames 0..", frame_count - 1));
  }
  if (range.last < range.first || range.last >= frame_count) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".last_frame ", range.last,
                                                   " is outside frames ", range.first, "..",
                                                   frame_count - 1));
  }
  return range;
}

}  // namespace motiondb::server
