// Refinement of the fast search's candidates (SearchParams::refine): a warp forced through its
// seed can score far worse than the best warp beside it (a seed anywhere in a held pose pins the
// warp there), enough to reorder nearly equal matches. The candidate is replaced by the best
// warp near it, found by banded warps (core/band_warp.h) re-centred on their own best path while
// that improves and touches the band's edge. From 45 Hz the band first moves at about 30 Hz
// (every n-th frame of query and clip, n = round(rate / 30): 1/n^2 of the cells), then settles
// at the full rate in a narrow band around where the coarse pass ended. A local search: scores
// only fall, but the best warp farther away than the band reaches is not found.
#ifndef MOTIONDB_CORE_SEARCH_WARP_REFINEMENT_H_
#define MOTIONDB_CORE_SEARCH_WARP_REFINEMENT_H_

#include <cstdint>
#include <vector>

#include "core/index/coordinate_view.h"
#include "core/search/search_result.h"
#include "core/search/warp/band_warp.h"
#include "core/search/warp/time_warp.h"

namespace motiondb {

// `candidate` (a result with its path) becomes the refined warp when that scores better: its
// range, score, path, and as seed_frame the clip frame it matches to `anchor`. `rate`: the
// frames per second of query and clip. `workspace`: one per thread.
void RefineCandidate(CoordinateView query, CoordinateView clip, int anchor, double rate,
                     const WarpConstraints& constraints, BandWorkspace& workspace,
                     SearchResult& candidate);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_WARP_REFINEMENT_H_
