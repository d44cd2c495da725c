#include "core/search/search_params.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/search/warp/time_warp.h"

namespace motiondb {
namespace {

absl::Status OutOfRange(absl::string_view name, double value, absl::string_view range) {
  return absl::InvalidArgumentError(
      absl::StrCat(name, " = ", value, " is out of range; expected ", range));
}

}  // namespace

const char* SeedSelectionName(SeedSelection selection) {
  switch (selection) {
    case SeedSelection::kDistinctPlaces:
      return "distinct_places";
    case SeedSelection::kNearestWindows:
      return "nearest_windows";
    case SeedSelection::kShapeWindows:
      return "shape_windows";
    case SeedSelection::kNearestFrames:
      break;
  }
  return "nearest_frames";
}

absl::Status ValidateSearchParams(const SearchParams& params, int dims) {
  const std::string dims_range = absl::StrCat("1..", dims, " (the library's dimensions)");
  if (params.ann_dims < 1 || params.ann_dims > dims) {
    return OutOfRange("ann_dims", params.ann_dims, dims_range);
  }
  if (params.dtw_dims < 1 || params.dtw_dims > dims) {
    return OutOfRange("dtw_dims", params.dtw_dims, dims_range);
  }
  if (params.excluded && (params.excluded->first_frame < 0 ||
                          params.excluded->last_frame < params.excluded->first_frame - 1)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "excluded: frames ", params.excluded->first_frame, "..", params.excluded->last_frame,
        " are not a range (0 <= first, first - 1 <= last)"));
  }
  if (params.neighbours < 0 || params.neighbours > 1'000'000) {
    return OutOfRange("neighbours", params.neighbours, "0..1000000 (0: by the library's size)");
  }
  if (params.places < 1 || params.places > 100'000) {
    return OutOfRange("places", params.places, "1..100000");
  }
  if (params.shape_windows < 1 || params.shape_windows > 100'000) {
    return OutOfRange("shape_windows", params.shape_windows, "1..100000");
  }
  if (params.shape_clips < 1 || params.shape_clips > 100'000) {
    return OutOfRange("shape_clips", params.shape_clips, "1..100000");
  }
  if (params.shape_lengths_either_side < 0 || params.shape_lengths_either_side > 8) {
    return OutOfRange("shape_lengths_either_side", params.shape_lengths_either_side, "0..8");
  }
  if (params.exact_threads < 0 || params.exact_threads > 1024) {
    return OutOfRange("exact_threads", params.exact_threads, "0..1024 (0: one per core)");
  }
  if (params.threads < 0 || params.threads > 1024) {
    return OutOfRange("threads", params.threads, "0..1024 (0: one per core)");
  }
  if (!std::isfinite(params.epsilon) || params.epsilon < 0) {
    return OutOfRange("epsilon", params.epsilon, "a finite value >= 0");
  }
  if (params.slope_limit < 1 || params.slope_limit > kMaxSlopeLimit) {
    return OutOfRange("slope_limit", params.slope_limit, absl::StrCat("1..", kMaxSlopeLimit));
  }
  if (params.max_results < 1 || params.max_results > kMaxSearchResults) {
    return OutOfRange("max_results", params.max_results, "1..10000");
  }
  if (!std::isfinite(params.cluster_gap_s) || params.cluster_gap_s < 0 ||
      params.cluster_gap_s > 60) {
    return OutOfRange("cluster_gap_s", params.cluster_gap_s, "0..60 seconds");
  }
  if (!std::isfinite(params.max_overlap) || params.max_overlap < 0 || params.max_overlap > 1) {
    return OutOfRange("max_overlap", params.max_overlap, "0..1");
  }
  if (params.characteristic_points < 0 || params.characteristic_points > kMaxCharacteristicPoints) {
    return OutOfRange("characteristic_points", params.characteristic_points,
                      absl::StrCat("0..", kMaxCharacteristicPoints, " (0: one per action)"));
  }
  if (params.characteristic_frames.size() > kMaxCharacteristicPoints) {
    return absl::InvalidArgumentError(absl::StrCat("characteristic_frames has ",
                                                   params.characteristic_frames.size(),
                                                   " frames; at most ", kMaxCharacteristicPoints));
  }
  if (!params.characteristic_frames.empty() && params.characteristic_frame != -1) {
    return absl::InvalidArgumentError(
        "characteristic_frame and characteristic_frames are both set; give one");
  }
  if (!std::isfinite(params.second_anchor_scatter) || params.second_anchor_scatter < 0 ||
      params.second_anchor_scatter > 1) {
    return OutOfRange("second_anchor_scatter", params.second_anchor_scatter, "0..1 (0: never)");
  }
  if (!std::isfinite(params.max_point_gap_s) || params.max_point_gap_s < 0 ||
      params.max_point_gap_s > 3600) {
    return OutOfRange("max_point_gap_s", params.max_point_gap_s, "0..3600 seconds");
  }
  return absl::OkStatus();
}

}  // namespace motiondb
