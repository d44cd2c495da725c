// The search through one characteristic point (thesis chapter 6, Algorithm 3): take the
// characteristic pose's nearest library frames as seeds, cluster the seeds in time per clip, warp
// the query through each cluster's best seed, and rank the warps by mean pose distance with
// overlap suppression. One step beyond the thesis (SearchParams::refine): the best warps are
// freed from their seeds, each moved to the best warp near it (core/warp_refinement.h), so that
// nearly equal matches are ordered by their true scores.
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_SINGLE_POINT_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_SINGLE_POINT_SEARCH_H_

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/internal/search_query.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// The search of `query` (two frames or more) through its frame `anchor`, in what `filter`
// admits. Search() and MultiPointSearch() call it with a query and parameters PrepareQuery
// checked, which it assumes. Thread-safe, as Search().
absl::StatusOr<SearchResponse> SinglePointSearch(const LibraryIndex& library, CoordinateView query,
                                                 int anchor, const SearchFilter& filter,
                                                 const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_SINGLE_POINT_SEARCH_H_
