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
#include <memory>
#include <new>
#include <optional>
#include <utility>
#include <vector>

#include "core/index/coordinate_view.h"
#include "util/stop_poll.h"

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

// std::allocator, but growing a vector of it leaves the new elements uninitialised: the warp
// writes every cell before it reads it, and clearing a long query's table on each growth took
// tens of milliseconds that no stop function can interrupt (and made every page resident).
template <typename T>
struct UninitializedAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <typename U>
  explicit UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
using WarpCells = std::vector<float, UninitializedAllocator<float>>;

// The bytes of the cost table an AnchoredWarp of a query of `rows` rows at `slope_limit` fills
// at most (its anchor at an end of the query, the clip long enough for the whole slope band):
// about 2 (slope_limit^2 - 1) rows^2, what a long query's warps cost in memory.
int64_t AnchoredWarpTableBytes(int64_t rows, int slope_limit);

// Reusable buffers for AnchoredWarp, so that warps allocate nothing once warm; one per thread.
struct WarpWorkspace {
  WarpCells cost[2];                 // the half-warp's cost table, and one row's distances
  std::vector<float> best_of_cell;   // per previous-row cell, the best over its pause states
  std::vector<int64_t> row_offsets;  // where each row starts in the cost table
  std::vector<float> frames;         // the clip frames the half-warp can reach, dims-major
  std::vector<std::pair<int64_t, int64_t>> computed;  // per row: the offsets filled in
  // How much of cost[0] has been written since it was allocated: the rows beyond lie on fresh
  // pages, whose first touch costs the kernel as much as thousands of cells (a StopPoll is told).
  int64_t touched = 0;
};

// The best warp of `query` onto `clip` that matches query frame `query_anchor` to clip frame
// `clip_anchor` (the thesis's two half-warps from the seed), or nullopt when no warp within the
// constraints fits inside the clip. Only the band of cells the slope limit can reach is filled.
// Early abandoning: also nullopt as soon as the warp's cost (the sum over the query's frames)
// is sure to reach `abandon_at`, i.e. it cannot beat what the caller already has. `stop`, when
// given, is told each row's cells as they are filled (a long query's warp takes hundreds of
// milliseconds): nullopt as soon as it says stop, which the caller tells from an abandoned warp
// by stop->stopped().
std::optional<Warp> AnchoredWarp(CoordinateView query, CoordinateView clip, int query_anchor,
                                 int64_t clip_anchor, const WarpConstraints& constraints,
                                 bool with_path, WarpWorkspace& workspace,
                                 float abandon_at = std::numeric_limits<float>::infinity(),
                                 StopPoll* stop = nullptr);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_WARP_TIME_WARP_H_
