#include "core/search/internal/pose_search.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/index/coarse_rate.h"
#include "core/search/internal/search_query.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// Places asked of the kd-tree per result wanted: ranked over ann_dims, they are re-ranked over
// dtw_dims, and moving to the best frame near each may bring two together.
constexpr int kPlacesPerResult = 4;

}  // namespace

absl::StatusOr<SearchResponse> PoseSearch(const LibraryIndex& library, CoordinateView pose,
                                          const SearchFilter& filter, const SearchParams& params) {
  const auto start = std::chrono::steady_clock::now();
  if (pose.rows != 1) return absl::InvalidArgumentError("a pose query has one frame");
  // One look: the work after it is bounded by max_results (a few milliseconds at most).
  if (SearchStop(params).Done(1)) return SearchStopped();
  SearchResponse response;
  SearchStats& stats = response.stats;
  stats.characteristic_frame = 0;
  stats.characteristic_frames = {0};
  const int64_t separation =
      std::max<int64_t>(std::llround(params.cluster_gap_s * library.rate()) + 1,
                        std::llround(kPoseSeparationS * library.rate()));
  const std::vector<Neighbour> places =
      library.NearestPlaces(pose.row(0), params.ann_dims, kPlacesPerResult * params.max_results,
                            separation, params.epsilon, filter);
  stats.seeds = stats.clusters = static_cast<int64_t>(places.size());
  stats.seeds_ms = MillisecondsSince(start);

  const auto stage = std::chrono::steady_clock::now();
  const int64_t reach = CoarseFactor(library.rate()) - 1;
  std::vector<SearchResult> candidates;
  candidates.reserve(places.size());
  for (const Neighbour& place : places) {
    const auto [clip, frame] = library.Locate(place.frame);
    // The kd-tree holds every n-th frame only (core/index/coarse_rate.h).
    const auto [nearest, distance] =
        library.NearestFrameAround(pose.row(0), params.dtw_dims, clip, frame, reach);
    SearchResult candidate;
    candidate.clip_index = clip;
    candidate.clip_id = library.clip(clip).clip_id;
    candidate.first_frame = candidate.last_frame = candidate.seed_frame = nearest;
    candidate.score = distance;
    // A result is its one frame (the range below only serves the overlap rule).
    if (filter.Admits(clip, candidate.seed_frame, candidate.seed_frame)) {
      candidates.push_back(std::move(candidate));
    }
  }
  stats.refine_ms = MillisecondsSince(stage);
  // One-frame results overlap only when equal: as `separation` frames from each, two overlap
  // exactly when closer than it, and the ranking's overlap rule drops the worse.
  SearchParams ranking = params;
  ranking.max_overlap = 0.0;
  for (SearchResult& candidate : candidates) {
    candidate.last_frame = candidate.seed_frame + separation - 1;
  }
  response.results = FinishResults(library, SearchFilter{}, std::move(candidates), ranking);
  for (SearchResult& result : response.results) {
    result.first_frame = result.last_frame = result.seed_frame;
    result.start_s = result.end_s = result.seed_frame / library.rate();
    if (params.return_path) result.path = {result.seed_frame};
  }
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
