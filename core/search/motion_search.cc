#include "core/search/motion_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/search/internal/search_query.h"
#include "core/search/warp/time_warp.h"
#include "core/search/warp_refinement.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using Clock = std::chrono::steady_clock;

// Refinement lowers scores, so it considers this many candidates per result returned: a warp
// pinned to a seed in a held pose can rank far below where its refined warp lands, and more
// seeds then crowd it out of a small pool. Measured (bench/RESULTS.md, issue 11; recall@10
// against the exact search, 10 h at 30 Hz): 2 gave 0.66, 4 gave 0.92 and 8 gave 0.95 for
// 0.3 ms more.
constexpr int kRefinePoolFactor = 8;
// This many candidates per result returned, the best after the coarse refinement, are settled
// at the full rate: 2 gave recall@10 0.92 at 10 h / 30 Hz, 4 gave 0.95 (coarse scores at 15 Hz
// order nearly equal matches less surely).
constexpr int kFinePoolFactor = 4;

struct Seed {
  int clip;
  int64_t frame;
  float distance;
};

// Per clip, runs of seed frames with gaps of at most `gap` frames (thesis 6.2.3). A run is
// represented by its nearest seed, and by every further seed that is the nearest within
// `separation` frames: with many seeds, runs merge across several instances separated by
// similar poses (the over-clustering of the thesis's Table 6.4), and one warp per run would
// find only one of them.
std::vector<Seed> ClusterSeeds(std::vector<Seed> seeds, int64_t gap, int64_t separation) {
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) {
    return a.clip != b.clip ? a.clip < b.clip : a.frame < b.frame;
  });
  std::vector<Seed> representatives;
  size_t run_start = 0;
  for (size_t i = 1; i <= seeds.size(); ++i) {
    const bool run_ends = i == seeds.size() || seeds[i].clip != seeds[i - 1].clip ||
                          seeds[i].frame - seeds[i - 1].frame > gap;
    if (!run_ends) continue;
    // Sorted in place: the runs still to come lie after i.
    const auto run_begin = seeds.begin() + run_start, run_end = seeds.begin() + i;
    std::sort(run_begin, run_end,
              [](const Seed& a, const Seed& b) { return a.distance < b.distance; });
    const size_t first_kept = representatives.size();
    for (auto seed_it = run_begin; seed_it != run_end; ++seed_it) {
      const Seed& seed = *seed_it;
      const bool near_kept = std::any_of(
          representatives.begin() + first_kept, representatives.end(),
          [&](const Seed& kept) { return std::abs(kept.frame - seed.frame) < separation; });
      if (!near_kept) representatives.push_back(seed);
    }
    run_start = i;
  }
  return representatives;
}

// Frames between distinct places in one clip. Measured on 1 h of synthetic capture at 30 Hz
// (10 queries, 128 places): a quarter of the query gave recall@10 0.78, half of it 0.61 (too
// few anchors inside one long instance for the warp to find its best alignment).
int64_t PlaceSeparation(int64_t gap, int64_t query_rows) {
  return std::max<int64_t>(gap + 1, query_rows / 4);
}

// The pool's candidates (warps at 1 / `factor` of the library's rate, with their paths) moved to
// the best warps near them; from a coarse rate, the best of them are then settled at the full
// rate.
absl::StatusOr<std::vector<SearchResult>> Refine(const LibraryIndex& library, CoordinateView query,
                                                 int anchor, int coarse_anchor, int factor,
                                                 const WarpConstraints& constraints,
                                                 const SearchParams& params,
                                                 std::vector<SearchResult> candidates) {
  BandWorkspace workspace;
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (i % 8 == 0) MOTIONDB_RETURN_IF_ERROR(CheckStop(params));
    SearchResult& candidate = candidates[i];
    RefineCandidate(CoarseView(query, factor),
                    CoarseView(library.clip_coordinates(candidate.clip_index), factor),
                    coarse_anchor, library.rate() / factor, constraints, workspace, candidate);
  }
  if (factor > 1) {
    candidates = RankResults(std::move(candidates), params.max_overlap,
                             params.max_results * kFinePoolFactor);
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (i % 8 == 0) MOTIONDB_RETURN_IF_ERROR(CheckStop(params));
      SearchResult& candidate = candidates[i];
      if (!RefineFromCoarse(query, library.clip_coordinates(candidate.clip_index), anchor, factor,
                            constraints, workspace, candidate)) {
        candidate.score = std::numeric_limits<double>::infinity();
      }
    }
    std::erase_if(candidates, [](const SearchResult& c) { return std::isinf(c.score); });
  }
  if (!params.return_path) {
    for (SearchResult& candidate : candidates) candidate.path = {};
  }
  return candidates;
}

}  // namespace

int FindCharacteristicFrame(CoordinateView query, int dims, NeutralPose neutral) {
  std::vector<double> centre(dims, 0.0);
  if (neutral == NeutralPose::kQueryMean) {
    for (int64_t f = 0; f < query.rows; ++f) {
      for (int k = 0; k < dims; ++k) centre[k] += query.row(f)[k];
    }
    for (double& c : centre) c /= static_cast<double>(query.rows);
  } else if (neutral == NeutralPose::kBoundaryMean) {
    for (int k = 0; k < dims; ++k) {
      centre[k] = 0.5 * (query.row(0)[k] + query.row(query.rows - 1)[k]);
    }
  }
  int best = 0;
  double best_distance = -1.0;
  for (int64_t f = 0; f < query.rows; ++f) {
    double sum = 0.0;
    for (int k = 0; k < dims; ++k) {
      const double d = query.row(f)[k] - centre[k];
      sum += d * d;
    }
    if (sum > best_distance) {
      best_distance = sum;
      best = static_cast<int>(f);
    }
  }
  return best;
}

absl::StatusOr<SearchResponse> Search(const LibraryIndex& library, CoordinateView query,
                                      const SearchParams& params) {
  const Clock::time_point start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<bool> allowed, PrepareQuery(library, query, params));
  SearchResponse response;
  SearchStats& stats = response.stats;

  Clock::time_point stage = Clock::now();
  const int anchor = params.characteristic_frame >= 0
                         ? params.characteristic_frame
                         : FindCharacteristicFrame(query, params.ann_dims, params.neutral);
  stats.characteristic_frame = anchor;
  stats.characteristic_ms = MillisecondsSince(stage);

  stage = Clock::now();
  const int64_t gap = std::max<int64_t>(1, std::llround(params.cluster_gap_s * library.rate()));
  const int64_t separation = std::max<int64_t>(gap + 1, query.rows / 2);
  const bool distinct = params.seed_selection == SeedSelection::kDistinctPlaces;
  const std::vector<Neighbour> neighbours =
      distinct ? library.NearestPlaces(query.row(anchor), params.ann_dims, params.places,
                                       PlaceSeparation(gap, query.rows), params.epsilon, allowed)
               : library.Nearest(query.row(anchor), params.ann_dims, params.neighbours,
                                 params.epsilon, allowed);
  stats.seeds = static_cast<int64_t>(neighbours.size());
  stats.seeds_ms = MillisecondsSince(stage);

  stage = Clock::now();
  std::vector<Seed> order;
  order.reserve(neighbours.size());
  for (const Neighbour& n : neighbours) {
    const auto [clip, frame] = library.Locate(n.frame);
    order.push_back({clip, frame, n.distance});
  }
  // Distinct places are their own clusters.
  if (!distinct) order = ClusterSeeds(std::move(order), gap, separation);
  stats.clusters = static_cast<int64_t>(order.size());
  stats.clusters_ms = MillisecondsSince(stage);

  // With refinement to follow, the warps run at about 15 Hz (core/index/coarse_rate.h).
  const int factor = params.refine ? CoarseFactor(library.rate()) : 1;
  const CoordinateView warp_query = CoarseView(query, factor);
  const int warp_anchor = static_cast<int>(
      std::min<int64_t>(std::lround(anchor / static_cast<double>(factor)), warp_query.rows - 1));
  const auto warp_clip = [&](int clip) {
    return CoarseView(library.clip_coordinates(clip), factor);
  };

  stage = Clock::now();
  // Nearest clusters first: good warps early make the abandoning threshold tight early.
  std::sort(order.begin(), order.end(),
            [](const Seed& a, const Seed& b) { return a.distance < b.distance; });
  const WarpConstraints constraints{params.slope_limit, params.dtw_dims};
  WarpWorkspace workspace;
  const int pool = params.refine ? params.max_results * kRefinePoolFactor : params.max_results;
  StreamingTopResults top(pool, params.max_overlap, warp_query.rows);
  for (size_t i = 0; i < order.size(); ++i) {
    if (i % 64 == 0) MOTIONDB_RETURN_IF_ERROR(CheckStop(params));
    const Seed& seed = order[i];
    const CoordinateView clip = warp_clip(seed.clip);
    const int64_t seed_frame =
        std::min<int64_t>(std::llround(seed.frame / static_cast<double>(factor)), clip.rows - 1);
    std::optional<Warp> warp =
        AnchoredWarp(warp_query, clip, warp_anchor, seed_frame, constraints,
                     params.return_path || params.refine, workspace, top.threshold());
    if (!warp) continue;
    ++stats.warps;
    top.Offer(MakeResult(seed.clip, *std::move(warp), seed.frame));
  }
  stats.warps_ms = MillisecondsSince(stage);

  stage = Clock::now();
  std::vector<SearchResult> candidates = top.Take();
  if (params.refine) {
    MOTIONDB_ASSIGN_OR_RETURN(candidates, Refine(library, query, anchor, warp_anchor, factor,
                                                 constraints, params, std::move(candidates)));
  }
  stats.refine_ms = MillisecondsSince(stage);

  stage = Clock::now();
  response.results = FinishResults(library, std::move(candidates), params);
  stats.ranking_ms = MillisecondsSince(stage);
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
