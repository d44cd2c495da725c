#include "core/search/internal/shape_search.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "core/index/coarse_rate.h"
#include "core/search/internal/clip_scan.h"
#include "core/search/internal/member_state.h"
#include "core/search/internal/settle_best.h"
#include "core/search/warp_refinement.h"
#include "util/status_macros.h"
#include "util/thread_team.h"

namespace motiondb {
namespace {

using Clock = std::chrono::steady_clock;

// The work of a window from the kd-trees as cells (kCellsPerStopPoll), as a seed's.
constexpr int64_t kCellsPerWindow = 1024;

// Coarse warps kept per result returned, each settled at the full rate: coarse scores order
// nearly equal matches less surely than full-rate ones. On 10 h of real capture (300 clips, 200
// windows a length; bench/notes/2026-12-07-shape-two-rate.md) 1 and 2 gave recall@10 0.990 and
// 0.995 at p50 4.7 and 5.7 ms; the settling costs 0.4 ms, the coarse pool's looser bound the
// rest.
constexpr int kCoarsePerResult = 2;

// Frames first..last of one clip to re-rank, and the nearest window's distance in it.
struct Range {
  int clip;
  int64_t first;
  int64_t last;
  float distance;
};

// The windows of the first `clips` distinct clips (nearest first), each widened by `widen`
// frames on both sides within its clip; one clip's overlapping or touching ranges merged. Nearest
// first: good warps early make the bound tight early.
std::vector<Range> CandidateRanges(const LibraryIndex& library, std::vector<ShapeWindow> windows,
                                   int clips, int64_t widen) {
  std::sort(windows.begin(), windows.end(),
            [](const ShapeWindow& a, const ShapeWindow& b) { return a.distance < b.distance; });
  absl::flat_hash_map<int, int> kept;  // clip -> its rank among the clips
  std::vector<Range> ranges;
  for (const ShapeWindow& w : windows) {
    auto it = kept.find(w.clip);
    if (it == kept.end()) {
      if (static_cast<int>(kept.size()) == clips) continue;
      kept.emplace(w.clip, static_cast<int>(kept.size()));
    }
    const int64_t frames = library.clip(w.clip).frame_count;
    ranges.push_back({w.clip, std::max<int64_t>(0, w.first_frame - widen),
                      std::min(frames - 1, w.first_frame + w.frames - 1 + widen), w.distance});
  }
  std::sort(ranges.begin(), ranges.end(), [](const Range& a, const Range& b) {
    return a.clip != b.clip ? a.clip < b.clip : a.first < b.first;
  });
  std::vector<Range> merged;
  for (const Range& r : ranges) {
    if (!merged.empty() && merged.back().clip == r.clip && r.first <= merged.back().last + 1) {
      merged.back().last = std::max(merged.back().last, r.last);
      merged.back().distance = std::min(merged.back().distance, r.distance);
    } else {
      merged.push_back(r);
    }
  }
  std::sort(merged.begin(), merged.end(),
            [](const Range& a, const Range& b) { return a.distance < b.distance; });
  return merged;
}

// The k best results of the subsequence warp of `query` over the disjoint `ranges`, each range
// read every `factor`-th frame from its first (the exact search's scan, its bounds and early
// abandoning over the ranges alone), in clip frames. Stats: warps, the ranges with a result.
absl::StatusOr<std::vector<SearchResult>> ScanRanges(
    const LibraryIndex& library, CoordinateView query, const std::vector<Range>& ranges, int factor,
    int k, const SearchParams& params, const SearchFilter& filter, StopPoll& stop,
    ClipScanWorkspace& workspace, SearchStats& stats) {
  FinishedClips finished(k, query.rows);
  StreamingTopResults top(k, params.max_overlap, query.rows);  // each range's, emptied by Take
  for (const Range& range : ranges) {
    const CoordinateView clip = CoarseView(
        library.clip_coordinates(range.clip).middle_rows(range.first, range.last - range.first + 1),
        factor);
    MOTIONDB_RETURN_IF_ERROR(ScanClip(
        query, clip, range.first, factor, range.clip, library.clip(range.clip).clip_id, params,
        filter, stop, [&] { return finished.bound(); }, workspace, top, stats));
    std::vector<SearchResult> results = top.Take();
    if (results.empty()) continue;
    ++stats.warps;
    finished.Add(std::move(results));
  }
  return finished.Take();
}

}  // namespace

absl::StatusOr<SearchResponse> ShapeSearch(const LibraryIndex& library, CoordinateView query,
                                           const SearchFilter& filter, const SearchParams& params) {
  const Clock::time_point start = Clock::now();
  SearchResponse response;
  SearchStats& stats = response.stats;
  // One thread: its coarse scan of the ranges is not shared out (SearchParams::threads).
  ThreadTeam team(1);
  std::vector<MemberState> members = {{SearchStop(params), {}, {}}};
  StopPoll& stop = members[0].stop;
  if (stop.Done(query.rows)) return SearchStopped();

  Clock::time_point stage = Clock::now();
  const int nearest = library.ShapeLengthNearest(query.rows);
  const int lengths = static_cast<int>(library.shape_lengths().size());
  std::vector<ShapeWindow> windows;
  for (int length = std::max(0, nearest - params.shape_lengths_either_side);
       length <= std::min(lengths - 1, nearest + params.shape_lengths_either_side); ++length) {
    for (const ShapeWindow& w :
         library.NearestShapes(query, length, params.shape_windows, params.epsilon, filter)) {
      windows.push_back(w);
    }
    if (stop.Done(kCellsPerWindow * params.shape_windows)) return SearchStopped();
  }
  stats.seeds = static_cast<int64_t>(windows.size());
  stats.seeds_ms = MillisecondsSince(stage);

  stage = Clock::now();
  const std::vector<Range> ranges =
      CandidateRanges(library, std::move(windows), params.shape_clips, query.rows / 2);
  stats.clusters = static_cast<int64_t>(ranges.size());
  stats.clusters_ms = MillisecondsSince(stage);

  // With refinement (the default), the ranges are warped at about 15 Hz as the fast search's
  // seeds are (1 / factor^2 of the cells), and the best coarse warps settled at the full rate
  // as the fast search's are; without, at the full rate.
  const int factor = params.refine ? CoarseFactor(library.rate()) : 1;
  ClipScanWorkspace workspace;
  stage = Clock::now();
  std::vector<SearchResult> best;
  if (factor == 1) {
    MOTIONDB_ASSIGN_OR_RETURN(best, ScanRanges(library, query, ranges, 1, params.max_results,
                                               params, filter, stop, workspace, stats));
    if (params.return_path) MOTIONDB_RETURN_IF_ERROR(AddPaths(library, query, params, 1, best));
    stats.warps_ms = MillisecondsSince(stage);
  } else {
    const CoordinateView coarse_query = CoarseView(query, factor);
    MOTIONDB_ASSIGN_OR_RETURN(
        std::vector<SearchResult> coarse,
        ScanRanges(library, coarse_query, ranges, factor, kCoarsePerResult * params.max_results,
                   params, filter, stop, workspace, stats));
    MOTIONDB_RETURN_IF_ERROR(AddPaths(library, coarse_query, params, factor, coarse));
    stats.warps_ms = MillisecondsSince(stage);
    stage = Clock::now();
    const size_t pool = coarse.size();
    MOTIONDB_ASSIGN_OR_RETURN(best, SettleBest(library, query, /*anchor=*/0, factor,
                                               {params.slope_limit, params.dtw_dims}, params,
                                               filter, std::move(coarse), pool, team, members));
    for (SearchResult& result : best) {
      result.seed_frame = -1;  // no seed, as the exact search's
      if (!params.return_path) result.path = {};
    }
    stats.refine_ms = MillisecondsSince(stage);
  }

  stage = Clock::now();
  response.results = FinishResults(library, filter, std::move(best), params);
  stats.ranking_ms = MillisecondsSince(stage);
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
