// What the fast and the exact search share: checking a query against a library, the clip filter,
// turning a warp into a result, and timing the stages.
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_SEARCH_QUERY_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_SEARCH_QUERY_H_

#include <chrono>
#include <vector>

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"
#include "core/search/warp/time_warp.h"
#include "util/stop_poll.h"

namespace motiondb {

// SearchParams' filters resolved against a library: the clips a search looks in, and the range
// of one that no result may overlap. As a FrameSelector, the frames the seed and shape searches
// may return: a seed inside the excluded range anchors only warps that overlap it.
struct SearchFilter : FrameSelector {
  using FrameSelector::Admits;
  // Whether a result in the clip of index `clip` over frames first..last may be returned.
  bool Admits(int clip, int64_t first, int64_t last) const {
    return clip != excluded_clip || last < excluded_first || first > excluded_last;
  }
  bool Admits(const SearchResult& result) const {
    return Admits(result.clip_index, result.first_frame, result.last_frame);
  }
};

// Checks the parameters and that the query has frames, the library's dimensions, and finite
// coordinates; returns the filters resolved. The one check of a search's parameters: the
// searches it dispatches to take its filter and do not check again.
absl::StatusOr<SearchFilter> PrepareQuery(const LibraryIndex& library, CoordinateView query,
                                          const SearchParams& params);

// A candidate: the clip by index and id (equal scores rank by id), the warp's frames and score.
// Its name and times are filled by FinishResults, only for the results kept.
SearchResult MakeResult(int clip_index, int64_t clip_id, Warp warp, int64_t seed_frame);

// The candidates `filter` admits, ranked (RankResults), then each kept result's clip id, name
// and start and end in seconds.
std::vector<SearchResult> FinishResults(const LibraryIndex& library, const SearchFilter& filter,
                                        std::vector<SearchResult> candidates,
                                        const SearchParams& params);

// Work between two polls of SearchParams::should_stop, in cells of a warp or of the exact
// search's scan (other work is counted as the cells it costs about as much as). A cell costs
// about a nanosecond, but the first touch of a fresh page of a warp's table costs as much as a
// thousand cells on this machine's virtual memory: so that a stop is seen within a few
// milliseconds even then, a poll every quarter million cells
// (bench/notes/2026-12-06-deadlines.md).
inline constexpr int64_t kCellsPerStopPoll = int64_t{1} << 18;

// A search's poll of its should_stop, counting cells.
inline StopPoll SearchStop(const SearchParams& params) {
  return StopPoll(params.should_stop, kCellsPerStopPoll);
}

// CANCELLED: what a search that its should_stop stopped returns.
absl::Status SearchStopped();

// Milliseconds since `start`, for SearchStats' timings.
double MillisecondsSince(std::chrono::steady_clock::time_point start);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_SEARCH_QUERY_H_
