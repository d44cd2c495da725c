// A pose query (issue 12): one frame in, the library's nearest distinct places to it out, with
// no warp: "find this pose" for an asset browser. Search() answers a one-frame query with it.
#ifndef MOTIONDB_CORE_SEARCH_POSE_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_POSE_SEARCH_H_

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// Places held apart in time, in seconds: a pose held for a second gives at most two results.
inline constexpr double kPoseSeparationS = 0.5;

// `pose`: one row, the library's dimensions. Each result is one frame (first = last =
// seed_frame) scored by its pose distance over `dtw_dims` (what a warp of one frame scores);
// of one clip, no two lie closer than kPoseSeparationS (or the cluster gap, if longer). The
// filters, max_results, ann_dims, epsilon and return_path (the one frame) apply as in Search();
// the warp's parameters are unused. Thread-safe, as Search().
absl::StatusOr<SearchResponse> PoseSearch(const LibraryIndex& library, CoordinateView pose,
                                          const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_POSE_SEARCH_H_
