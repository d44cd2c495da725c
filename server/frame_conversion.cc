#include "server/frame_conversion.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace motiondb::server {
namespace {

// The first frame of 0..count - 1 where `before` turns false (it is true, then false). Written
// out rather than std::ranges::partition_point over std::views::iota: clang 14 (the fuzz build's
// compiler) cannot compile libstdc++ 12's iota_view.
template <typename Predicate>
int64_t PartitionPoint(int64_t count, const Predicate& before) {
  int64_t low = 0, high = count;
  while (low < high) {
    const int64_t middle = low + (high - low) / 2;
    if (before(middle)) {
      low = middle + 1;
    } else {
      high = middle;
    }
  }
  return low;
}

}  // namespace

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
  const int64_t first =
      PartitionPoint(space_frames_, [&](int64_t s) { return ToOriginal(s) < range.first; });
  const int64_t after =
      PartitionPoint(space_frames_, [&](int64_t s) { return ToOriginal(s) <= range.last; });
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
