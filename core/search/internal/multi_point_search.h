// A search through several characteristic points (thesis 7.2.3): for a query made of several
// actions, one warp through one point must fit every timing difference between the actions
// into one slope-limited path, and a pause held longer in the library than in the query cannot
// fit at all. Here the query is cut between adjacent points into parts (around a pose held
// between them, halfway when there is none), each part is searched through its own point
// (seeds, clusters, warps, refinement: SinglePointSearch()), and in every clip the parts' matches
// are chained in query order through a directed graph whose edges join a match of one part to a
// match of the next that starts after it ends, at most max_point_gap_s later than the held pose
// between them lasts in the query. The held pose's rows are matched to one clip frame where the
// two matches join, a pause of any length. The best chain ending at each match is a result: its
// score is the mean pose distance over all the query's frames, its path the parts' paths (and
// the pauses) end to end.
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_MULTI_POINT_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_MULTI_POINT_SEARCH_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/internal/search_query.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// The search of `query` through `anchors` (two or more increasing query frames), in what
// `filter` admits; Search() calls it when a query has several points, after checking the query
// and the parameters (PrepareQuery), which it assumes. Thread-safe, as Search().
absl::StatusOr<SearchResponse> MultiPointSearch(const LibraryIndex& library, CoordinateView query,
                                                const std::vector<int>& anchors,
                                                const SearchFilter& filter,
                                                const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_MULTI_POINT_SEARCH_H_
