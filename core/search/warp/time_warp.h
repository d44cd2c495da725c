// Dynamic time warping of a query onto a library clip (thesis 6.2.4).
//
// The warp model, shared by the fast and the exact search: every query frame i is matched to
// one clip frame w(i); from one query frame to the next the clip advances by 0 to slope_limit
// frames, with at most slope_limit - 1 pauses in a row. The warp therefore never runs more than
// slope_limit times faster or slower than the query, every warp has exactly one cell per query
// frame, and its score, the mean pose distance along the path, is minimised exactly by the
// dynamic programme.
#ifndef MOTIONDB_CORE_SEARCH_WARP_TIME_WARP_H_
#define MOTIONDB_CORE_SEARCH_WARP_TIME_WARP_H_

#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "core/index/coordinate_view.h"

namespace motiondb {

// The thesis's warp defaults (Table 6.2), which the search's parameters start from too.
inline constexpr int kDefaultSlopeLimit = 2;
inline constexpr int kDefaultWarpDims = 5;

struct WarpConstraints {
  // Clip frames advance 0..slope_limit per query frame, pausing at most slope_limit - 1 times
  // in a row; 1 means no warping at all. At most kMaxSlopeLimit.
  int slope_limit = kDefaultSlopeLimit;
  // Dimensions of the pose distance.
  int dims = kDefaultWarpDims;
};

inline constexpr int kMaxSlopeLimit = 8;

struct Warp {
  int64_t first = 0;          // clip frame matched to the first query frame
  int64_t last = 0;           // clip frame matched to the last query frame
  double score = 0;           // mean pose distance along the path
  std::vector<int64_t> path;  // clip frame of every query frame, when requested
};

// Reusable buffers for AnchoredWarp, so that warps allocate nothing once warm; one per thread.
struct WarpWorkspace {
  std::vector<float> cost[2];        // the half-warp's cost table, and one row's distances
  std::vector<float> best_of_cell;   // per previous-row cell, the best over its pause states
  std::vector<int64_t> row_offsets;  // where each row starts in the cost table
  std::vector<float> frames;         // the clip frames the half-warp can reach, dims-major
  std::vector<std::pair<int64_t, int64_t>> computed;  // per row: the offsets filled in
};

// The best warp of `query` onto `clip` that matches query frame `query_anchor` to clip frame
// `clip_anchor` (the thesis's two half-warps from the seed), or nullopt when no warp within the
// constraints fits inside the clip. Only the band of cells the slope limit can reach is filled.
// Early abandoning: also nullopt as soon as the warp's cost (the sum over the query's frames)
// is sure to reach `abandon_at`, i.e. it cannot beat what the caller already has.
std::optional<Warp> AnchoredWarp(CoordinateView query, CoordinateView clip, int query_anchor,
                                 int64_t clip_anchor, const WarpConstraints& constraints,
                                 bool with_path, WarpWorkspace& workspace,
                                 float abandon_at = std::numeric_limits<float>::infinity());

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_WARP_TIME_WARP_H_
