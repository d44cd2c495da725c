#include "core/search/motion_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/search/internal/search_query.h"
#include "core/search/warp/time_warp.h"
#include "core/search/warp_refinement.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using Clock = std::chrono::steady_clock;

// Refinement lowers scores, so it considers this many candidates per result returned.
constexpr int kRefinePoolFactor = 2;

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

  stage = Clock::now();
  // Nearest clusters first: good warps early make the abandoning threshold tight early.
  std::sort(order.begin(), order.end(),
            [](const Seed& a, const Seed& b) { return a.distance < b.distance; });
  const WarpConstraints constraints{params.slope_limit, params.dtw_dims};
  WarpWorkspace workspace;
  const int pool = params.refine ? params.max_results * kRefinePoolFactor : params.max_results;
  StreamingTopResults top(pool, params.max_overlap, query.rows);
  for (size_t i = 0; i < order.size(); ++i) {
    if (i % 64 == 0) MOTIONDB_RETURN_IF_ERROR(CheckStop(params));
    const Seed& seed = order[i];
    std::optional<Warp> warp =
        AnchoredWarp(query, library.clip_coordinates(seed.clip), anchor, seed.frame, constraints,
                     params.return_path || params.refine, workspace, top.threshold());
    if (!warp) continue;
    ++stats.warps;
    top.Offer(MakeResult(seed.clip, *std::move(warp), seed.frame));
  }
  stats.warps_ms = MillisecondsSince(stage);

  stage = Clock::now();
  std::vector<SearchResult> candidates = top.Take();
  if (params.refine) {
    BandWorkspace band_workspace;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (i % 8 == 0) MOTIONDB_RETURN_IF_ERROR(CheckStop(params));
      SearchResult& candidate = candidates[i];
      RefineCandidate(query, library.clip_coordinates(candidate.clip_index), anchor, library.rate(),
                      constraints, band_workspace, candidate);
      if (!params.return_path) candidate.path = {};
    }
  }
  stats.refine_ms = MillisecondsSince(stage);

  stage = Clock::now();
  response.results = FinishResults(library, std::move(candidates), params);
  stats.ranking_ms = MillisecondsSince(stage);
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
