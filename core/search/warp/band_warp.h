// A time warp confined to a band around a given warp: every query frame i may match a clip
// frame within `radius` of the given warp's frame for i, with a free start and end inside the
// band, under the warp model of core/time_warp.h. The fast search uses it to free each
// candidate from its seed: a warp forced through its seed can score a little worse than the
// best warp beside it, enough to reorder nearly equal matches. Cost: query frames x
// (2 radius + 1) x slope_limit cells, a fraction of one anchored warp.
#ifndef MOTIONDB_CORE_SEARCH_WARP_BAND_WARP_H_
#define MOTIONDB_CORE_SEARCH_WARP_BAND_WARP_H_

#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "core/index/coordinate_view.h"
#include "core/search/warp/time_warp.h"

namespace motiondb {

// Reusable buffers for BandWarp; one per thread.
struct BandWorkspace {
  std::vector<float> cost;  // per row: slope_limit states x (2 radius + 1) frames, padded
  std::vector<float> distances;
  std::vector<float> frames;       // the clip frames the band covers, dims-major
  std::vector<int64_t> row_first;  // per row: the clip frame of the band's first cell
};

// The best warp in the band around `centre` (a clip frame per query frame, advancing 0..s
// frames per row, such as a warp's path), with its path; never worse than `centre` when that is
// itself a warp of the model. Sets `*touches_edge` when the best path reaches the band's edge
// somewhere other than the clip's ends: a wider band, or one around the new path, might do
// better still. Early abandoning: nullopt, as soon as it is sure, when the warp's cost (the sum
// over the query's frames) exceeds `abandon_at` (`*touches_edge` is then unspecified). `stop`,
// when given, is told each row's cells: nullopt as soon as it says stop (AnchoredWarp's).
std::optional<Warp> BandWarp(CoordinateView query, CoordinateView clip,
                             const std::vector<int64_t>& centre, int radius,
                             const WarpConstraints& constraints, BandWorkspace& workspace,
                             bool* touches_edge,
                             float abandon_at = std::numeric_limits<float>::infinity(),
                             StopPoll* stop = nullptr);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_WARP_BAND_WARP_H_
