// Exact search: an exhaustive subsequence time warp of the query over every library frame,
// under the same warp model as the fast search (core/time_warp.h), returning the best
// non-overlapping matches. A match is, for a clip frame, the best warp ending there (over every
// start): the subsequence-DTW matching function. The ground truth for the fast search's recall,
// and an option for small libraries.
//
// Two devices keep it usable on hours of data without changing its answer: early abandoning
// (a partial path whose cost already exceeds the current k-th best total is dropped) and a
// lower bound per block of clip frames (the distance of every query frame to the bounding box of
// the frames a path from that block can reach; blocks whose bound exceeds the k-th best are
// skipped). Non-overlap selection is greedy over the streamed per-end-frame optima of each
// clip. Clips are scanned on `exact_threads` threads; the results do not depend on how many.
#ifndef MOTIONDB_CORE_SEARCH_EXACT_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_EXACT_SEARCH_H_

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// Uses dtw_dims, slope_limit, max_results, max_overlap, return_path, exact_threads, the
// filters and should_stop (called from every scanning thread) of `params`; the seed parameters
// do not apply. Thread-safe like Search().
absl::StatusOr<SearchResponse> ExactSearch(const LibraryIndex& library, CoordinateView query,
                                           const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_EXACT_SEARCH_H_
