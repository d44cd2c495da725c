// Query-by-example search in a library (thesis chapter 6, Algorithm 3): find the query's
// characteristic pose, take its nearest library frames as seeds, cluster the seeds in time per
// clip, warp the query through each cluster's best seed, and rank the warps by mean pose
// distance with overlap suppression. One step beyond the thesis (SearchParams::refine): the
// best warps are freed from their seeds, each moved to the best warp near it
// (core/warp_refinement.h), so that nearly equal matches are ordered by their true scores.
#ifndef MOTIONDB_CORE_SEARCH_MOTION_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_MOTION_SEARCH_H_

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// `query`: the query's projection at the library's rate, pre-scaled like the library, with the
// library's dimensions; a query of one frame is a pose query (pose_search.h), one with several
// characteristic points a multi-point search (multi_point_search.h). Thread-safe: any number of
// searches may run on one library at once.
absl::StatusOr<SearchResponse> Search(const LibraryIndex& library, CoordinateView query,
                                      const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_MOTION_SEARCH_H_
