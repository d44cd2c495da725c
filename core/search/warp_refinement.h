// Refinement of the fast search's candidates (SearchParams::refine): a warp forced through its
// seed can score far worse than the best warp beside it (a seed anywhere in a held pose pins the
// warp there), enough to reorder nearly equal matches. The candidate is replaced by the best
// warp near it, found by banded warps (core/band_warp.h) re-centred on their own best path while
// that improves and touches the band's edge. The fast search warps and refines at about 15 Hz
// first (CoarseView: 1/n^2 of the cells) and settles at the full rate in a narrow band around
// the coarse path (RefineFromCoarse). A local search: scores only fall, but the best warp
// farther away than the band reaches is not found.
#ifndef MOTIONDB_CORE_SEARCH_WARP_REFINEMENT_H_
#define MOTIONDB_CORE_SEARCH_WARP_REFINEMENT_H_

#include <cstdint>
#include <vector>

#include "core/index/coarse_rate.h"
#include "core/index/coordinate_view.h"
#include "core/search/search_result.h"
#include "core/search/warp/band_warp.h"
#include "core/search/warp/time_warp.h"

namespace motiondb {

// Every `factor`-th row of `view`, from row 0, read in place.
inline CoordinateView CoarseView(CoordinateView view, int factor) {
  return {view.data, (view.rows - 1) / factor + 1, view.stride * factor};
}

// Every factor-th frame of `clip` from `phase`: what a warp at 1 / factor of the rate sees when
// `phase` is its seed's frame modulo factor, so that the seed is among them. Fixed from frame 0
// instead, an instance whose best alignment falls between those frames scored worse at the
// coarse rate than its peers: at 100 h of synthetic capture, recall@10 against the exact search
// rose from 0.74 to 0.77 with the seeds' phases kept.
inline CoordinateView PhasedView(CoordinateView clip, int factor, int64_t phase) {
  return CoarseView(clip.middle_rows(phase, clip.rows - phase), factor);
}

// A candidate's frames (range, seed frame, path) between PhasedView's (coarse) and the clip's
// own: x <-> x * factor + phase.
void ToClipFrames(int factor, int64_t phase, SearchResult& candidate);
void ToCoarseFrames(int factor, int64_t phase, SearchResult& candidate);

// `candidate` (a result with its path) becomes the best warp near it when that scores better:
// its range, score, path, and as seed_frame the clip frame it matches to `anchor`. `rate`: the
// frames per second of query and clip, which sets the band's width. `workspace`: one per thread.
// `stop` (optional) is told the band warps' cells; once it says stop, the candidate may be left
// as it was.
void RefineCandidate(CoordinateView query, CoordinateView clip, int anchor, double rate,
                     const WarpConstraints& constraints, BandWorkspace& workspace,
                     SearchResult& candidate, StopPoll* stop = nullptr);

// `candidate`, a warp of CoarseView(query, factor) onto every factor-th frame of `clip` with its
// path, its frames given as the clip's own, becomes the best full-rate warp in a narrow band
// around it (whatever its score: coarse and full-rate scores are not comparable); false when
// the band holds no warp within the constraints, or when a band's best warp scores over
// `abandon_score` (the candidate is then unchanged). The bound is a band's, not the settling's:
// a band whose best path touches its edge would be followed by one around that path, which can
// score under the bound, so a candidate can be given up that would have settled just under it.
// `stop` as RefineCandidate's: false once it says stop.
bool RefineFromCoarse(CoordinateView query, CoordinateView clip, int anchor, int factor,
                      const WarpConstraints& constraints, double abandon_score,
                      BandWorkspace& workspace, SearchResult& candidate, StopPoll* stop = nullptr);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_WARP_REFINEMENT_H_
