#include "core/search/internal/shape_search.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "core/search/internal/clip_scan.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using Clock = std::chrono::steady_clock;

// The work of a window from the kd-trees as cells (kCellsPerStopPoll), as a seed's.
constexpr int64_t kCellsPerWindow = 1024;

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

}  // namespace

absl::StatusOr<SearchResponse> ShapeSearch(const LibraryIndex& library, CoordinateView query,
                                           const SearchFilter& filter, const SearchParams& params) {
  const Clock::time_point start = Clock::now();
  SearchResponse response;
  SearchStats& stats = response.stats;
  StopPoll stop = SearchStop(params);
  if (stop.Done(query.rows)) return SearchStopped();

  Clock::time_point stage = Clock::now();
  const int nearest = library.ShapeLengthNearest(query.rows);
  const int lengths = static_cast<int>(library.shape_lengths().size());
  std::vector<ShapeWindow> windows;
  for (int length = std::max(0, nearest - params.shape_lengths_either_side);
       length <= std::min(lengths - 1, nearest + params.shape_lengths_either_side); ++length) {
    for (const ShapeWindow& w : library.NearestShapes(query, length, params.shape_windows,
                                                      params.epsilon, filter.allowed)) {
      // A window inside the excluded range would take a clip's place for results it cannot give.
      const bool excluded = w.clip == filter.excluded_clip &&
                            w.first_frame >= filter.excluded_first &&
                            w.first_frame + w.frames - 1 <= filter.excluded_last;
      if (!excluded) windows.push_back(w);
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

  stage = Clock::now();
  // The ranges of one clip are disjoint, so the exact search's shared bound holds as it does
  // over whole clips.
  FinishedClips finished(params.max_results, query.rows);
  for (const Range& range : ranges) {
    StreamingTopResults top(params.max_results, params.max_overlap, query.rows);
    const CoordinateView clip =
        library.clip_coordinates(range.clip).middle_rows(range.first, range.last - range.first + 1);
    MOTIONDB_RETURN_IF_ERROR(ScanClip(
        query, clip, range.first, range.clip, params, filter, stop,
        [&] { return finished.bound(); }, top, stats));
    std::vector<SearchResult> results = top.Take();
    if (results.empty()) continue;
    ++stats.warps;
    finished.Add(std::move(results));
  }
  std::vector<SearchResult> best = finished.Take();
  if (params.return_path) MOTIONDB_RETURN_IF_ERROR(AddPaths(library, query, params, best));
  stats.warps_ms = MillisecondsSince(stage);

  stage = Clock::now();
  response.results = FinishResults(library, filter, std::move(best), params);
  stats.ranking_ms = MillisecondsSince(stage);
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
