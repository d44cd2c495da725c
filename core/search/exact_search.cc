#include "core/search/exact_search.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <mutex>
#include <optional>

#include "absl/functional/function_ref.h"
#include "absl/strings/str_cat.h"
#include "core/search/internal/search_query.h"
#include "core/search/warp/time_warp.h"
#include "util/parallel_for.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Clip frames per lower-bound block.
constexpr int64_t kBlock = 32;

// The subsequence warp of one clip: columns are clip frames (in order), rows query frames,
// states the pauses in a row. Only the last slope_limit columns are kept.
class ClipScan {
 public:
  ClipScan(CoordinateView query, CoordinateView clip, int slope_limit, int dims)
      : query_(query),
        clip_(clip),
        s_(slope_limit),
        dims_(dims),
        m_(query.rows),
        ring_(slope_limit + 1) {
    for (Column& column : ring_) {
      column.cost.assign(m_ * s_, kInfinity);
      column.start.assign(m_ * s_, 0);
    }
    lower_bound_.resize(m_ + 1);
    ComputeBlockBoxes();
  }

  // Runs over every column, offering each end frame's best path to `top`.
  // `bound()` is a cost that no result of other clips at or above it can rank with: paths
  // that cannot stay below it and below the clip's own k-th best are dropped. `stop` is told
  // each column's cells (a column of a long query costs as much as many short ones).
  absl::Status Run(int clip_index, const SearchFilter& filter, StopPoll& stop,
                   absl::FunctionRef<float()> bound, StreamingTopResults& top, SearchStats& stats) {
    const auto threshold = [&] { return std::min(top.threshold(), bound()); };
    for (int64_t j = 0; j < clip_.rows; ++j) {
      // Every column is cleared, m x s cells, whatever it then fills.
      if (stop.Done(m_ * s_)) return SearchStopped();
      if (j % kBlock == 0) {
        BlockLowerBound(j);
        if (!AnyAlive() && lower_bound_[0] >= threshold()) {
          // No path can start in this block and beat the k-th best: skip it.
          const int64_t skip = std::min(kBlock, clip_.rows - j);
          for (int64_t k = 0; k < std::min<int64_t>(skip, s_ + 1); ++k) {
            ring_[(j + k) % ring_.size()].top = -1;
          }
          j += skip - 1;
          ++stats.pruned_blocks;
          continue;
        }
      }
      const float end_cost = FillColumn(j, threshold(), stats);
      const int64_t best_start = ring_[j % ring_.size()].best_start;
      if (end_cost < kInfinity && filter.Admits(clip_index, best_start, j)) {
        const Warp warp{best_start, j, end_cost / static_cast<double>(m_), {}};
        top.Offer(MakeResult(clip_index, warp, -1));
      }
    }
    return absl::OkStatus();
  }

 private:
  struct Column {
    std::vector<float> cost;     // m x s
    std::vector<int64_t> start;  // clip frame of the path's first query frame
    int64_t top = -1;            // highest row with a finite cost
    int64_t best_start = 0;
  };

  bool AnyAlive() const {
    return std::any_of(ring_.begin(), ring_.end(), [](const Column& c) { return c.top >= 0; });
  }

  // Fills column j; returns the best total over the last row (infinity when none).
  float FillColumn(int64_t j, float threshold, SearchStats& stats) {
    Column& column = ring_[j % ring_.size()];
    std::fill(column.cost.begin(), column.cost.end(), kInfinity);
    // Rows reachable: one above the previous columns' top, plus pauses within this column.
    int64_t reach = 0;
    for (int advance = 1; advance <= s_ && advance <= j; ++advance) {
      reach = std::max(reach, ring_[(j - advance) % ring_.size()].top + 1);
    }
    reach = std::min<int64_t>(m_ - 1, reach + s_ - 1);
    column.top = -1;
    const float* x = clip_.row(j);
    for (int64_t i = 0; i <= reach; ++i) {
      float best = kInfinity;
      int64_t best_start = 0;
      if (i == 0) {
        best = 0.0f;
        best_start = j;
      } else {
        for (int advance = 1; advance <= s_ && advance <= j; ++advance) {
          const Column& from = ring_[(j - advance) % ring_.size()];
          if (from.top < i - 1) continue;
          for (int z = 0; z < s_; ++z) {
            const float c = from.cost[(i - 1) * s_ + z];
            if (c < best) {
              best = c;
              best_start = from.start[(i - 1) * s_ + z];
            }
          }
        }
      }
      const float* pause = i > 0 ? &column.cost[(i - 1) * s_] : nullptr;
      const bool can_pause = pause != nullptr && std::any_of(pause, pause + s_ - 1,
                                                             [](float c) { return c < kInfinity; });
      if (best == kInfinity && !can_pause) continue;
      const float d = Distance(query_.row(i), x, dims_);
      ++stats.cells;
      const float bound = threshold - lower_bound_[i + 1];
      if (best + d < bound) {
        column.cost[i * s_] = best + d;
        column.start[i * s_] = best_start;
        column.top = i;
      }
      for (int z = 1; z < s_ && can_pause; ++z) {
        const float c = pause[z - 1] + d;
        if (c < bound) {
          column.cost[i * s_ + z] = c;
          column.start[i * s_ + z] = column.start[(i - 1) * s_ + z - 1];
          column.top = i;
        }
      }
    }
    if (column.top < m_ - 1) return kInfinity;
    float best = kInfinity;
    for (int z = 0; z < s_; ++z) {
      if (column.cost[(m_ - 1) * s_ + z] < best) {
        best = column.cost[(m_ - 1) * s_ + z];
        column.best_start = column.start[(m_ - 1) * s_ + z];
      }
    }
    return best;
  }

  void ComputeBlockBoxes() {
    const int64_t blocks = (clip_.rows + kBlock - 1) / kBlock;
    box_low_.assign(blocks * dims_, kInfinity);
    box_high_.assign(blocks * dims_, -kInfinity);
    for (int64_t f = 0; f < clip_.rows; ++f) {
      const int64_t b = f / kBlock;
      for (int k = 0; k < dims_; ++k) {
        box_low_[b * dims_ + k] = std::min(box_low_[b * dims_ + k], clip_.row(f)[k]);
        box_high_[b * dims_ + k] = std::max(box_high_[b * dims_ + k], clip_.row(f)[k]);
      }
    }
  }

  // lower_bound_[i]: a lower bound on the cost of query rows i.. for any path with a cell in
  // the block starting at column j0: each row's distance to the box of every frame such a path
  // can reach, [j0, j0 + kBlock - 1 + s * (m - 1)].
  void BlockLowerBound(int64_t j0) {
    const int64_t last = std::min(clip_.rows - 1, j0 + kBlock - 1 + s_ * (m_ - 1));
    std::vector<float> low(dims_, kInfinity), high(dims_, -kInfinity);
    for (int64_t b = j0 / kBlock; b <= last / kBlock; ++b) {
      for (int k = 0; k < dims_; ++k) {
        low[k] = std::min(low[k], box_low_[b * dims_ + k]);
        high[k] = std::max(high[k], box_high_[b * dims_ + k]);
      }
    }
    lower_bound_[m_] = 0.0f;
    for (int64_t i = m_ - 1; i >= 0; --i) {
      float sum = 0.0f;
      for (int k = 0; k < dims_; ++k) {
        const float v = query_.row(i)[k];
        const float outside = v < low[k] ? low[k] - v : (v > high[k] ? v - high[k] : 0.0f);
        sum += outside * outside;
      }
      // Slightly loosened so float rounding can never prune a path that would have won.
      lower_bound_[i] = lower_bound_[i + 1] + 0.999f * std::sqrt(sum);
    }
  }

  CoordinateView query_;
  CoordinateView clip_;
  int s_;
  int dims_;
  int64_t m_;
  std::vector<Column> ring_;
  std::vector<float> lower_bound_;
  std::vector<float> box_low_, box_high_;
};

// The k best results of the clips scanned so far, shared by the scanning threads, and the
// warp cost bound they set for the clips still being scanned. Thread-safe.
//
// Each clip is scanned with its own streaming top (its results depend on the clip alone) and
// pruned by this bound besides. Pruning drops only paths that cost at least the bound, and the
// bound (the k-th best of finished clips, which can only fall) is never below the final k-th
// best: the results that rank are the same whatever the order and the number of threads.
class FinishedClips {
 public:
  FinishedClips(int k, int64_t query_rows) : k_(k), query_rows_(query_rows) {}

  float bound() const { return bound_.load(std::memory_order_relaxed); }

  void Add(std::vector<SearchResult> results) {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::move(results.begin(), results.end(), std::back_inserter(best_));
    // Results of different clips never overlap, and one clip's never overlap each other.
    best_ = RankResults(std::move(best_), /*max_overlap=*/1.0, k_);
    if (static_cast<int>(best_.size()) == k_) {
      // Loosened a little, so that float rounding never prunes a path that ties the k-th.
      bound_.store(static_cast<float>(best_.back().score * query_rows_ * (1 + 1e-5)),
                   std::memory_order_relaxed);
    }
  }

  std::vector<SearchResult> Take() { return std::move(best_); }

 private:
  const int k_;
  const int64_t query_rows_;
  std::mutex mutex_;
  std::vector<SearchResult> best_;
  std::atomic<float> bound_{kInfinity};
};

// Gives each result its path. The scan keeps no back-pointers (a column of costs and starts
// per clip frame); a result is the best warp ending at its last frame, which is what a warp
// anchored at the query's last frame there computes again, with its path, for k results only.
absl::Status AddPaths(const LibraryIndex& library, CoordinateView query, const SearchParams& params,
                      std::vector<SearchResult>& results) {
  WarpWorkspace workspace;
  StopPoll stop = SearchStop(params);
  for (SearchResult& result : results) {
    if (stop.Done(query.rows)) return SearchStopped();
    std::optional<Warp> warp = AnchoredWarp(
        query, library.clip_coordinates(result.clip_index), static_cast<int>(query.rows - 1),
        result.last_frame, {params.slope_limit, params.dtw_dims}, /*with_path=*/true, workspace,
        std::numeric_limits<float>::infinity(), &stop);
    if (stop.stopped()) return SearchStopped();
    if (!warp) {
      return absl::InternalError(absl::StrCat("no warp ends at frame ", result.last_frame,
                                              " of clip ", result.clip_index,
                                              ", where the exact search found one"));
    }
    // Among equal warps the scan and the anchored warp may keep different starts.
    result.first_frame = warp->first;
    result.path = std::move(warp->path);
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<SearchResponse> ExactSearch(const LibraryIndex& library, CoordinateView query,
                                           const SearchParams& params) {
  const auto start = std::chrono::steady_clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const SearchFilter filter, PrepareQuery(library, query, params));
  SearchResponse response;
  const auto warps = std::chrono::steady_clock::now();
  FinishedClips finished(params.max_results, query.rows);
  std::vector<SearchStats> stats(ThreadsFor(params.exact_threads));
  MOTIONDB_RETURN_IF_ERROR(ParallelFor(
      library.clip_count(), static_cast<int>(stats.size()),
      [&](int64_t index, int thread) -> absl::Status {
        const int c = static_cast<int>(index);
        if (!filter.allowed.empty() && !filter.allowed[c]) return absl::OkStatus();
        // Each thread polls on its own; every one of them stops within a poll's work.
        StopPoll stop = SearchStop(params);
        if (stop.Done(query.rows)) return SearchStopped();
        StreamingTopResults top(params.max_results, params.max_overlap, query.rows);
        ClipScan scan(query, library.clip_coordinates(c), params.slope_limit, params.dtw_dims);
        MOTIONDB_RETURN_IF_ERROR(scan.Run(
            c, filter, stop, [&] { return finished.bound(); }, top, stats[thread]));
        // Most clips hold nothing under the bound: adding nothing would only take the lock.
        std::vector<SearchResult> results = top.Take();
        if (!results.empty()) finished.Add(std::move(results));
        return absl::OkStatus();
      }));
  for (const SearchStats& thread_stats : stats) {
    response.stats.cells += thread_stats.cells;
    response.stats.pruned_blocks += thread_stats.pruned_blocks;
  }
  response.stats.warps_ms = MillisecondsSince(warps);
  std::vector<SearchResult> best = finished.Take();
  if (params.return_path) MOTIONDB_RETURN_IF_ERROR(AddPaths(library, query, params, best));
  response.results = FinishResults(library, filter, std::move(best), params);
  response.stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
