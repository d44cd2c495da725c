// The exact search's subsequence time warp over one clip, or over a range of one, with its early
// abandoning and block lower bounds (core/search/exact_search.h), for the exact search and for
// the re-ranking of the shape candidates (core/search/internal/shape_search.h).
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_CLIP_SCAN_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_CLIP_SCAN_H_

#include <atomic>
#include <cstdint>
#include <limits>
#include <mutex>
#include <vector>

#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/internal/search_query.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"
#include "util/stop_poll.h"

namespace motiondb {

// The scan's buffers, kept by the caller across scans (one per thread), so that scans allocate
// nothing once these have held the longest query and range: the shape search scans hundreds of
// short ranges a query.
struct ClipScanWorkspace {
  struct Column {
    std::vector<float> cost;     // m x s
    std::vector<int64_t> start;  // clip frame of the path's first query frame
    int64_t top = -1;            // highest row with a finite cost
    int64_t best_start = 0;
  };
  std::vector<Column> ring;  // the last slope_limit + 1 columns
  std::vector<float> lower_bound;
  std::vector<float> box_low, box_high;  // per block of clip frames
  std::vector<float> low, high;
};

// Offers to `top` the best warp of `query` ending at each row of `clip`, the frames
// first_frame, first_frame + frame_step, ... of the library's clip `clip_index` (the whole clip:
// first_frame 0, frame_step 1; a CoarseView of a range: its factor), that `filter` admits, in
// the clip's frames. `bound()`: a warp cost (a sum over the query's frames)
// that no result at or above it can rank with; paths that cannot stay under it and under `top`'s
// threshold are dropped. Uses slope_limit and dtw_dims of `params`; `stop` is told every
// column's cells. Adds its cells and skipped blocks to `stats`.
absl::Status ScanClip(CoordinateView query, CoordinateView clip, int64_t first_frame,
                      int frame_step, int clip_index, int64_t clip_id, const SearchParams& params,
                      const SearchFilter& filter, StopPoll& stop, absl::FunctionRef<float()> bound,
                      ClipScanWorkspace& workspace, StreamingTopResults& top, SearchStats& stats);

// The k best results of the clips (or disjoint ranges of clips) scanned so far, shared by the
// scanning threads, and the warp cost bound they set for the clips still being scanned.
// Thread-safe.
//
// Each clip is scanned with its own streaming top (its results depend on the clip alone) and
// pruned by this bound besides. Pruning drops only paths that cost at least the bound, and the
// bound (the k-th best of finished clips, which can only fall) is never below the final k-th
// best: the results that rank are the same whatever the order and the number of threads.
class FinishedClips {
 public:
  FinishedClips(int k, int64_t query_rows) : k_(k), query_rows_(query_rows) {}

  float bound() const { return bound_.load(std::memory_order_relaxed); }

  // `results` must overlap none of those added before (results of other clips, or of a
  // disjoint range of the same clip).
  void Add(std::vector<SearchResult> results);

  std::vector<SearchResult> Take() { return std::move(best_); }

 private:
  const int k_;
  const int64_t query_rows_;
  std::mutex mutex_;
  std::vector<SearchResult> best_;
  std::atomic<float> bound_{std::numeric_limits<float>::infinity()};
};

// Gives each result its path. The scan keeps no back-pointers (a column of costs and starts
// per clip frame); a result is the best warp ending at its last frame, which is what a warp
// anchored at the query's last frame there computes again, with its path, for k results only.
// `factor`: the scan's frame_step, `query` then the CoarseView the scan warped (the results'
// frames and paths stay the clip's own).
absl::Status AddPaths(const LibraryIndex& library, CoordinateView query, const SearchParams& params,
                      int factor, std::vector<SearchResult>& results);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_CLIP_SCAN_H_
