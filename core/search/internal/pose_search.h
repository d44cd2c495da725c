// The pose query's search (core/search/pose_search.h), for Search() and the several-point
// search's one-frame parts.
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_POSE_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_POSE_SEARCH_H_

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/internal/search_query.h"
#include "core/search/pose_search.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// `pose`: one row, the library's dimensions. Each result is one frame (first = last =
// seed_frame) scored by its pose distance over `dtw_dims` (what a warp of one frame scores);
// of one clip, no two lie closer than kPoseSeparationS (or the cluster gap, if longer). The
// filters, max_results, ann_dims, epsilon and return_path (the one frame) apply as in Search();
// the warp's parameters are unused. `filter`: what PrepareQuery made of the parameters, which
// it checked. Thread-safe, as Search().
absl::StatusOr<SearchResponse> PoseSearch(const LibraryIndex& library, CoordinateView pose,
                                          const SearchFilter& filter, const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_POSE_SEARCH_H_
