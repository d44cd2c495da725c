#include "core/search/internal/single_point_search.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/search/characteristic_points.h"
#include "core/search/internal/member_state.h"
#include "core/search/internal/search_query.h"
#include "core/search/internal/settle_best.h"
#include "core/search/warp/time_warp.h"
#include "core/search/warp_refinement.h"
#include "util/parallel_for.h"
#include "util/status_macros.h"
#include "util/thread_team.h"

namespace motiondb {
namespace {

using Clock = std::chrono::steady_clock;

// Refinement lowers scores, so it considers this many candidates per result returned, per
// thousand seeds (for fewer seeds, as for a thousand): a warp pinned to a seed in a held pose
// can rank far below where its refined warp lands, and more seeds crowd it out of a small pool.
// Measured (bench/notes/2026-12-02-scale-seeds.md; recall@10 against the exact search):
// 1 h at 30 Hz, pools of 2 and 4 per result gave 0.81 and 0.95; 10 h, 4 and 8 gave 0.92 and
// 0.95; 100 h, 2000 seeds, 16 and 24 gave 0.87 and 0.95.
constexpr double kRefinePoolPerThousandSeeds = 12;
// Seed windows need half of it: their warps start nearer where refinement ends. Measured with
// 500 windows (bench/notes/2026-12-05-scale-window-seeds.md; recall@10, p50), 12 / 6 / 4 per
// thousand: 10 h of real capture 0.945 / 0.945 / 0.945 (5.0 / 4.3 / 4.1 ms), 10 h at 30 Hz
// 0.985 / 0.980 / 0.960 (3.8 / 2.9 / 2.8 ms), 10 h at 120 Hz 0.970 / 0.965 / 0.935 (6.5 / 4.7 /
// 3.9 ms), 1 h 1.000 / 1.000 / 0.990, 70 s at 120 Hz 0.995 each.
constexpr double kWindowRefinePoolPerThousandSeeds = 6;

double RefinePoolPerThousandSeeds(SeedSelection selection) {
  return selection == SeedSelection::kNearestWindows ? kWindowRefinePoolPerThousandSeeds
                                                     : kRefinePoolPerThousandSeeds;
}
// The best this share of the refined pool are settled at the full rate from the coarse rate:
// coarse scores order nearly equal matches less surely the denser the library, and a settle
// costs factor^2 times a coarse one. Measured over 20 queries each
// (bench/notes/2026-12-04-scale-o3.md; recall@10 against the exact search): at factor 2, two
// thirds gave 0.945 at 10 h and 0.925 at 100 h, all of it 0.950 (2.8 ms) and 0.955 (9.2 ms); at
// 10 h / 120 Hz (factor 8) a third gave 0.925 (3.4 ms), half 0.950 (4.1 ms), two thirds 0.960
// (4.7 ms).
double FineShare(int factor) { return factor <= 2 ? 1.0 : 2.0 / 3.0; }

// The default seeds are taken again, twice as many, at most this many times while they fall in
// fewer than kClustersPerResult clusters a result, and while a doubling adds clusters. Measured
// on 70 s at 120 Hz (one clip; 20 queries, bench/notes/2026-12-05-scale-window-seeds.md): 500 seed
// windows fell in
// 23 clusters and filled 16.1 of 20 results, 1000 in 40 clusters and 19.9.
constexpr int kMostSeedDoublings = 3;
constexpr size_t kClustersPerResult = 2;

// Seed windows (SeedSelection::kNearestWindows) spread over more places than nearest frames do,
// so fewer of them cover as much: on 10 h of real capture
// (bench/notes/2026-12-05-scale-window-seeds.md, 20 queries; recall@10 against the exact search)
// 250, 500 and 1000 gave 0.875, 0.945 and 0.975 (3.8, 5.5 and 8.7 ms with the nearest frames'
// refinement pool), where 1000 nearest frames give 0.940 (6.5 ms).
constexpr int kWindowSeeds = 500;

// The seeds of the nearest-frames selection when the search does not say: the thesis's 1000 up
// to 10 hours of 15 Hz seed frames in the kd-tree, then 1000 more per tenfold (100 h: 2000).
// Measured at 100 h of synthetic capture at 30 Hz with every candidate refined: 1000 seeds gave
// recall@10 0.88, 2000 gave 0.95 (8.2 ms). Windows: kWindowSeeds.
int NearestFrameSeeds(const LibraryIndex& library, const SearchParams& params) {
  if (params.neighbours > 0) return params.neighbours;
  if (params.seed_selection == SeedSelection::kNearestWindows) return kWindowSeeds;
  constexpr double kTenHoursOfSeeds = 10 * 3600 * kCoarseRate;
  const double tree_frames = static_cast<double>(library.total_frames()) / library.tree_every();
  return static_cast<int>(
      std::lround(1000 * (1 + std::log10(std::max(1.0, tree_frames / kTenHoursOfSeeds)))));
}

// The work of a seed as cells (kCellsPerStopPoll): a neighbour from the kd-tree took about a
// microsecond, and clustering about 300 ns a seed (1,000,000 neighbours asked of 1 h at 30 Hz).
constexpr int64_t kCellsPerNeighbour = 1024;
constexpr int64_t kCellsPerClusteredSeed = 256;

struct Seed {
  int clip;
  int64_t frame;
  float distance;
  int anchor = 0;  // the query frame the seed's warp passes through
};

// Per clip, runs of seed frames with gaps of at most `gap` frames (thesis 6.2.3). A run is
// represented by its nearest seed, and by every further seed that is the nearest within
// `separation` frames: with many seeds, runs merge across several instances separated by
// similar poses (the over-clustering of the thesis's Table 6.4), and one warp per run would
// find only one of them. Counts its work in `stop`, and returns early once it says stop.
std::vector<Seed> ClusterSeeds(std::vector<Seed> seeds, int64_t gap, int64_t separation,
                               StopPoll& stop) {
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
      // A seed costs about 300 cells (its sorts); a run of many seeds far apart keeps many of
      // them, each compared with the others.
      if (stop.Done(kCellsPerClusteredSeed +
                    static_cast<int64_t>(representatives.size() - first_kept))) {
        return representatives;
      }
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

// The pool's candidates (warps at 1 / `factor` of the library's rate with their paths, in clip
// frames) moved to the best warps near them; from a coarse rate, the best of them are then
// settled at the full rate (those `filter` admits). On several threads, the same candidates as
// on one: refinement moves each candidate alone, and the settles are judged in order
// (SettleBest).
absl::StatusOr<std::vector<SearchResult>> Refine(
    const LibraryIndex& library, CoordinateView query, int anchor, int coarse_anchor, int factor,
    const WarpConstraints& constraints, const SearchParams& params, const SearchFilter& filter,
    std::vector<SearchResult> candidates, ThreadTeam& team, std::vector<MemberState>& members) {
  MOTIONDB_RETURN_IF_ERROR(team.ParallelFor(
      static_cast<int64_t>(candidates.size()), [&](int64_t i, int m) -> absl::Status {
        SearchResult& candidate = candidates[i];
        StopPoll& stop = members[m].stop;
        if (stop.Done(static_cast<int64_t>(candidate.path.size()))) return SearchStopped();
        const int64_t phase = candidate.first_frame % factor;
        ToCoarseFrames(factor, phase, candidate);
        RefineCandidate(CoarseView(query, factor),
                        PhasedView(library.clip_coordinates(candidate.clip_index), factor, phase),
                        coarse_anchor, library.rate() / factor, constraints, members[m].bands,
                        candidate, &stop);
        if (stop.stopped()) return SearchStopped();
        ToClipFrames(factor, phase, candidate);
        return absl::OkStatus();
      }));
  if (factor > 1) {
    const size_t fine_pool =
        std::max<size_t>(params.max_results,
                         std::lround(FineShare(factor) * static_cast<double>(candidates.size())));
    MOTIONDB_ASSIGN_OR_RETURN(
        candidates, SettleBest(library, query, anchor, factor, constraints, params, filter,
                               std::move(candidates), fine_pool, team, members));
  }
  if (!params.return_path) {
    for (SearchResult& candidate : candidates) candidate.path = {};
  }
  return candidates;
}

// Query frame `frame`'s row (the nearest) in the CoarseView of `coarse_rows` rows at 1 / factor.
int CoarseRow(int frame, int factor, int64_t coarse_rows) {
  return static_cast<int>(
      std::min<int64_t>(std::lround(frame / static_cast<double>(factor)), coarse_rows - 1));
}

// The seeds the warps are anchored at, clustered in time: the nearest frames (or windows) to the
// characteristic pose `anchor` (or distinct places), the default count taken again while they
// fall in too few places (kMostSeedDoublings), half of them at a second anchor when they scatter
// (SearchParams::second_anchor_scatter). `coarse_rows`, `factor`: the warps' query. Fills the
// seed and cluster stages' stats. Counts its work in `stop`, and returns early once it says stop.
std::vector<Seed> ClusteredSeeds(const LibraryIndex& library, CoordinateView query, int anchor,
                                 int64_t coarse_rows, int factor, const SearchFilter& filter,
                                 const SearchParams& params, SearchStats& stats, StopPoll& stop) {
  Clock::time_point stage = Clock::now();
  const int64_t gap = std::max<int64_t>(1, std::llround(params.cluster_gap_s * library.rate()));
  const int64_t separation = std::max<int64_t>(gap + 1, query.rows / 2);
  const bool distinct = params.seed_selection == SeedSelection::kDistinctPlaces;
  int seed_count = NearestFrameSeeds(library, params);
  const auto nearest_of = [&](int query_frame, int count) {
    switch (params.seed_selection) {
      case SeedSelection::kDistinctPlaces:
        return library.NearestPlaces(query.row(query_frame), params.ann_dims, params.places,
                                     PlaceSeparation(gap, query.rows), params.epsilon, filter);
      case SeedSelection::kNearestWindows:
        return library.NearestWindows(query, query_frame, params.ann_dims, count, params.epsilon,
                                      filter);
      case SeedSelection::kNearestFrames:
      case SeedSelection::kShapeWindows:  // Search() runs the shape search instead
        break;
    }
    return library.Nearest(query.row(query_frame), params.ann_dims, count, params.epsilon, filter);
  };
  // A warp pins its query row CoarseRow(anchor) to its seed and samples the clip every factor-th
  // frame from there, but the kd-tree holds only every tree_every()-th frame of the library: a
  // seed as found can be a frame out of step with the query, and then so is every sample of its
  // warp (a take's exact copy an odd number of frames after it scored as a near copy does, and
  // refinement never saw it: bench/notes/2026-12-07-copy-miss.md). So each seed moves to the
  // frame nearest the pinned query frame's pose, up to a sampling step either side.
  const int64_t reach = std::max(library.tree_every(), factor) - 1;
  const auto seeds_of = [&](int query_frame, int count) {
    const std::vector<Neighbour> neighbours = nearest_of(query_frame, count);
    // A move compares a cell's worth of pose for each frame it looks at.
    stop.Done((kCellsPerNeighbour + 2 * reach + 1) * static_cast<int64_t>(neighbours.size()));
    const float* pinned = query.row(CoarseRow(query_frame, factor, coarse_rows) * factor);
    std::vector<Seed> seeds;
    seeds.reserve(neighbours.size());
    for (const Neighbour& n : neighbours) {
      const auto [clip, found] = library.Locate(n.frame);
      const int64_t frame =
          reach > 0 ? library.NearestFrameAround(pinned, params.dtw_dims, clip, found, reach).first
                    : found;
      seeds.push_back({clip, frame, n.distance, query_frame});
    }
    return seeds;
  };
  std::vector<Seed> nearest = seeds_of(anchor, seed_count);  // nearest first
  stats.seeds_ms = MillisecondsSince(stage);

  stage = Clock::now();
  // Distinct places are their own clusters.
  std::vector<Seed> order = distinct ? nearest : ClusterSeeds(nearest, gap, separation, stop);
  const bool scattered = !distinct && params.second_anchor_scatter > 0 && nearest.size() >= 2 &&
                         static_cast<double>(order.size()) >
                             params.second_anchor_scatter * static_cast<double>(nearest.size());
  double reseed_ms = 0;
  // Seeds by the library's default count that pile into too few places to fill max_results (a
  // short library, a pose held long) are taken again, twice as many, while the library has
  // more and they reach more places. (Scattered seeds are in many places already.)
  const size_t wanted_clusters = kClustersPerResult * static_cast<size_t>(params.max_results);
  for (int more = 0; !stop.stopped() && !distinct && !scattered && params.neighbours == 0 &&
                     more < kMostSeedDoublings && order.size() < wanted_clusters &&
                     nearest.size() == static_cast<size_t>(seed_count);
       ++more) {
    seed_count *= 2;
    const Clock::time_point again = Clock::now();
    std::vector<Seed> more_seeds = seeds_of(anchor, seed_count);
    reseed_ms += MillisecondsSince(again);
    std::vector<Seed> more_order = ClusterSeeds(more_seeds, gap, separation, stop);
    if (more_order.size() <= order.size()) break;  // no new places: the seeds piled up anyway
    nearest = std::move(more_seeds);
    order = std::move(more_order);
  }
  stats.seeds = static_cast<int64_t>(nearest.size());
  int second = scattered ? FindSecondAnchor(query, anchor, params.ann_dims) : -1;
  // The warps pass their anchor's row at the coarse rate, where the two must differ.
  if (second >= 0 &&
      CoarseRow(second, factor, coarse_rows) == CoarseRow(anchor, factor, coarse_rows)) {
    second = -1;
  }
  double second_seeds_ms = 0;
  if (second >= 0) {
    const size_t half = nearest.size() / 2;
    const int rest = static_cast<int>(nearest.size() - half);
    nearest.resize(half);
    order = ClusterSeeds(std::move(nearest), gap, separation, stop);
    const Clock::time_point second_start = Clock::now();
    std::vector<Seed> second_seeds = seeds_of(second, rest);
    second_seeds_ms = MillisecondsSince(second_start);
    stats.seeds = static_cast<int64_t>(half + second_seeds.size());
    std::vector<Seed> more = ClusterSeeds(std::move(second_seeds), gap, separation, stop);
    order.insert(order.end(), more.begin(), more.end());
    stats.second_anchor = second;
  }
  stats.clusters = static_cast<int64_t>(order.size());
  stats.seeds_ms += reseed_ms + second_seeds_ms;
  stats.clusters_ms = MillisecondsSince(stage) - reseed_ms - second_seeds_ms;
  return order;
}

}  // namespace

absl::StatusOr<SearchResponse> SinglePointSearch(const LibraryIndex& library, CoordinateView query,
                                                 int anchor, const SearchFilter& filter,
                                                 const SearchParams& params) {
  const Clock::time_point start = Clock::now();
  SearchResponse response;
  SearchStats& stats = response.stats;
  stats.characteristic_frame = anchor;
  stats.characteristic_frames = {anchor};

  // With refinement to follow, the warps run at about 15 Hz (core/index/coarse_rate.h).
  const int factor = params.refine ? CoarseFactor(library.rate()) : 1;
  const CoordinateView warp_query = CoarseView(query, factor);
  const int warp_anchor = CoarseRow(anchor, factor, warp_query.rows);

  // Started now, so that the helpers are running by the time the seeds are found.
  ThreadTeam team(ThreadsFor(params.threads));
  std::vector<MemberState> members(team.size(), {SearchStop(params), {}, {}});
  stats.threads = static_cast<int>(members.size());
  StopPoll& stop = members[0].stop;
  if (stop.Done(query.rows)) return SearchStopped();
  std::vector<Seed> order =
      ClusteredSeeds(library, query, anchor, warp_query.rows, factor, filter, params, stats, stop);
  if (stop.stopped()) return SearchStopped();

  Clock::time_point stage = Clock::now();
  // Nearest clusters first: good warps early make the abandoning threshold tight early.
  std::sort(order.begin(), order.end(),
            [](const Seed& a, const Seed& b) { return a.distance < b.distance; });
  const WarpConstraints constraints{params.slope_limit, params.dtw_dims};
  const int pool =
      params.refine ? static_cast<int>(std::lround(
                          params.max_results * RefinePoolPerThousandSeeds(params.seed_selection) *
                          std::max(1.0, static_cast<double>(stats.seeds) / 1000.0)))
                    : params.max_results;
  StreamingTopResults top(pool, params.max_overlap, warp_query.rows);
  const bool keep_path = params.return_path || params.refine;
  struct SeedWarp {
    std::optional<Warp> warp;
    float abandon_at = 0;  // the threshold it was warped against
  };
  std::vector<SeedWarp> warps(order.size());
  const auto warp_seed = [&](size_t i, float abandon_at, MemberState& member) {
    // A warp's cells are counted as it fills them; its setup costs about a row's.
    if (member.stop.Done(warp_query.rows)) return SearchStopped();
    const Seed& seed = order[i];
    const int64_t phase = seed.frame % factor;
    // A second anchor's warp needs its path to say where it passes the characteristic frame.
    warps[i] = {
        AnchoredWarp(warp_query, PhasedView(library.clip_coordinates(seed.clip), factor, phase),
                     CoarseRow(seed.anchor, factor, warp_query.rows), seed.frame / factor,
                     constraints, keep_path || seed.anchor != anchor, member.warps, abandon_at,
                     &member.stop),
        abandon_at};
    return member.stop.stopped() ? SearchStopped() : absl::OkStatus();
  };
  // On several threads each seed is warped against the threshold its thread last saw, and
  // offered in order: a warp given up against a lower threshold than its offer sees (the
  // threshold rises when a candidate suppresses two kept ones) is warped again, so that the
  // pool holds what one thread would have kept.
  std::atomic<float> threshold{top.threshold()};
  MOTIONDB_RETURN_IF_ERROR(team.ParallelForInOrder(
      static_cast<int64_t>(order.size()),
      [&](int64_t i, int t) { return warp_seed(i, threshold.load(), members[t]); },
      [&](int64_t i, int t) -> absl::Status {
        // Also warped again: a warp completed against a higher threshold than the offer sees
        // whose cost is about at it (the pool's double scores and the warp's float threshold
        // can disagree at a tie).
        const float now = top.threshold();
        const std::optional<Warp>& warp = warps[i].warp;
        if (warp ? warps[i].abandon_at > now &&
                       warp->score * static_cast<double>(warp_query.rows) >= now * (1 - 1e-5)
                 : warps[i].abandon_at < now) {
          MOTIONDB_RETURN_IF_ERROR(warp_seed(i, now, members[t]));
        }
        if (!warps[i].warp) return absl::OkStatus();
        ++stats.warps;
        const Seed& seed = order[i];
        SearchResult candidate = MakeResult(seed.clip, library.clip(seed.clip).clip_id,
                                            *std::move(warps[i].warp), seed.frame / factor);
        ToClipFrames(factor, seed.frame % factor, candidate);
        if (seed.anchor != anchor) {
          candidate.seed_frame = candidate.path[warp_anchor];
          if (!keep_path) candidate.path = {};
        }
        // Left out before it takes a place in the pool that an admitted one would have had.
        if (filter.Admits(candidate)) top.Offer(std::move(candidate));
        threshold = top.threshold();
        return absl::OkStatus();
      }));
  stats.warps_ms = MillisecondsSince(stage);

  stage = Clock::now();
  std::vector<SearchResult> candidates = top.Take();
  if (params.refine) {
    MOTIONDB_ASSIGN_OR_RETURN(
        candidates, Refine(library, query, anchor, warp_anchor, factor, constraints, params, filter,
                           std::move(candidates), team, members));
  }
  stats.refine_ms = MillisecondsSince(stage);

  stage = Clock::now();
  response.results = FinishResults(library, filter, std::move(candidates), params);
  stats.ranking_ms = MillisecondsSince(stage);
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
