// The last step of a search at about 15 Hz (core/index/coarse_rate.h): its best coarse warps
// settled at the full rate, each by RefineFromCoarse in a narrow band around its path, the
// settles abandoned over a bound that no settled warp above it can rank with. The fast search
// settles its refined pool so (core/search/single_point_search.cc); the shape search, its coarse
// re-ranking's best (core/search/shape_search.cc).
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_SETTLE_BEST_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_SETTLE_BEST_H_

#include <cstddef>
#include <vector>

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/internal/member_state.h"
#include "core/search/internal/search_query.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"
#include "core/search/warp/time_warp.h"
#include "util/thread_team.h"

namespace motiondb {

// `candidates`: warps of CoarseView(query, factor) with their paths, in clip frames. The best
// `fine_pool` of them by coarse score (ranked with params.max_overlap), and the next best while
// the settled hold fewer than params.max_results ranked places, each moved to the best full-rate
// warp near it (`anchor`: the query frame whose clip frame becomes its seed_frame); those that
// settle where `filter` admits them (a band can move a warp into the excluded range), unranked,
// with their full-rate paths. Each member's stop is told its band warps' cells. On the team's
// threads the same as on one: each settle is judged, in order, against the bound the settles
// before it left (ThreadTeam::ParallelForInOrder).
absl::StatusOr<std::vector<SearchResult>> SettleBest(
    const LibraryIndex& library, CoordinateView query, int anchor, int factor,
    const WarpConstraints& constraints, const SearchParams& params, const SearchFilter& filter,
    std::vector<SearchResult> candidates, size_t fine_pool, ThreadTeam& team,
    std::vector<MemberState>& members);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_SETTLE_BEST_H_
