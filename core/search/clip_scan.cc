#include "core/search/internal/clip_scan.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>

#include "absl/strings/str_cat.h"
#include "core/search/warp/time_warp.h"
#include "core/search/warp_refinement.h"

namespace motiondb {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Clip frames per lower-bound block.
constexpr int64_t kBlock = 32;

// The subsequence warp of one clip: columns are clip frames (in order), rows query frames,
// states the pauses in a row. Only the last slope_limit columns are kept.
class ClipScan {
 public:
  ClipScan(CoordinateView query, CoordinateView clip, int64_t first_frame, int frame_step,
           int slope_limit, int dims, ClipScanWorkspace& workspace)
      : query_(query),
        clip_(clip),
        first_frame_(first_frame),
        frame_step_(frame_step),
        s_(slope_limit),
        dims_(dims),
        m_(query.rows),
        ring_(workspace.ring),
        lower_bound_(workspace.lower_bound),
        box_low_(workspace.box_low),
        box_high_(workspace.box_high),
        low_(workspace.low),
        high_(workspace.high) {
    ring_.resize(slope_limit + 1);
    for (Column& column : ring_) {
      column.cost.assign(m_ * s_, kInfinity);
      column.start.assign(m_ * s_, 0);
      column.top = -1;
      column.best_start = 0;
    }
    lower_bound_.resize(m_ + 1);
    ComputeBlockBoxes();
  }

  // Runs over every column, offering each end frame's best path to `top`.
  // `bound()` is a cost that no result of other clips at or above it can rank with: paths
  // that cannot stay below it and below the clip's own k-th best are dropped. `stop` is told
  // each column's cells (a column of a long query costs as much as many short ones).
  absl::Status Run(int clip_index, int64_t clip_id, const SearchFilter& filter, StopPoll& stop,
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
      const int64_t first = first_frame_ + frame_step_ * best_start;
      const int64_t last = first_frame_ + frame_step_ * j;
      if (end_cost < kInfinity && filter.Admits(clip_index, first, last)) {
        const Warp warp{first, last, end_cost / static_cast<double>(m_), {}};
        top.Offer(MakeResult(clip_index, clip_id, warp, -1));
      }
    }
    return absl::OkStatus();
  }

 private:
  using Column = ClipScanWorkspace::Column;

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
    low_.assign(dims_, kInfinity);
    high_.assign(dims_, -kInfinity);
    for (int64_t b = j0 / kBlock; b <= last / kBlock; ++b) {
      for (int k = 0; k < dims_; ++k) {
        low_[k] = std::min(low_[k], box_low_[b * dims_ + k]);
        high_[k] = std::max(high_[k], box_high_[b * dims_ + k]);
      }
    }
    lower_bound_[m_] = 0.0f;
    for (int64_t i = m_ - 1; i >= 0; --i) {
      float sum = 0.0f;
      for (int k = 0; k < dims_; ++k) {
        const float v = query_.row(i)[k];
        const float outside = v < low_[k] ? low_[k] - v : (v > high_[k] ? v - high_[k] : 0.0f);
        sum += outside * outside;
      }
      // Slightly loosened so float rounding can never prune a path that would have won.
      lower_bound_[i] = lower_bound_[i + 1] + 0.999f * std::sqrt(sum);
    }
  }

  CoordinateView query_;
  CoordinateView clip_;
  int64_t first_frame_;  // clip_'s row 0 in its clip
  int64_t frame_step_;   // clip frames between clip_'s rows
  int s_;
  int dims_;
  int64_t m_;
  // The workspace's buffers.
  std::vector<Column>& ring_;
  std::vector<float>& lower_bound_;
  std::vector<float>&box_low_, &box_high_;
  std::vector<float>&low_, &high_;  // the box of a block's reach
};

}  // namespace

absl::Status ScanClip(CoordinateView query, CoordinateView clip, int64_t first_frame,
                      int frame_step, int clip_index, int64_t clip_id, const SearchParams& params,
                      const SearchFilter& filter, StopPoll& stop, absl::FunctionRef<float()> bound,
                      ClipScanWorkspace& workspace, StreamingTopResults& top, SearchStats& stats) {
  ClipScan scan(query, clip, first_frame, frame_step, params.slope_limit, params.dtw_dims,
                workspace);
  return scan.Run(clip_index, clip_id, filter, stop, bound, top, stats);
}

void FinishedClips::Add(std::vector<SearchResult> results) {
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

absl::Status AddPaths(const LibraryIndex& library, CoordinateView query, const SearchParams& params,
                      int factor, std::vector<SearchResult>& results) {
  WarpWorkspace workspace;
  StopPoll stop = SearchStop(params);
  for (SearchResult& result : results) {
    if (stop.Done(query.rows)) return SearchStopped();
    const int64_t phase = result.last_frame % factor;
    std::optional<Warp> warp =
        AnchoredWarp(query, PhasedView(library.clip_coordinates(result.clip_index), factor, phase),
                     static_cast<int>(query.rows - 1), result.last_frame / factor,
                     {params.slope_limit, params.dtw_dims}, /*with_path=*/true, workspace,
                     std::numeric_limits<float>::infinity(), &stop);
    if (stop.stopped()) return SearchStopped();
    if (!warp) {
      return absl::InternalError(absl::StrCat("no warp ends at frame ", result.last_frame,
                                              " of clip ", result.clip_index,
                                              ", where the exact search found one"));
    }
    // Among equal warps the scan and the anchored warp may keep different starts.
    result.first_frame = warp->first * factor + phase;
    result.path = std::move(warp->path);
    for (int64_t& frame : result.path) frame = frame * factor + phase;
  }
  return absl::OkStatus();
}

}  // namespace motiondb
