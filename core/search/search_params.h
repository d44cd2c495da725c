// Parameters of a query-by-example search (thesis chapter 6, Table 6.2 defaults).
#ifndef MOTIONDB_CORE_SEARCH_SEARCH_PARAMS_H_
#define MOTIONDB_CORE_SEARCH_SEARCH_PARAMS_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/index/library_index.h"
#include "core/search/warp/time_warp.h"

namespace motiondb {

// The neutral pose the characteristic point is farthest from (thesis 6.2.1).
enum class NeutralPose {
  kQueryMean,     // the mean of the query's poses
  kBoundaryMean,  // the mean of the query's first and last poses
  kOrigin,        // the space origin: the training set's mean pose
};

// How the fast search picks the library frames its warps are anchored at. Both work at about
// 15 Hz when refinement follows (core/index/coarse_rate.h).
enum class SeedSelection {
  // The thesis (6.2.2-6.2.3): the `neighbours` nearest frames, clustered in time. With seeds in
  // the warp's dimensions at about 15 Hz and a refinement pool of 8 per result, recall@10
  // against the exact search is 0.95-1.0 on synthetic capture from 70 s to 10 h and 0.98 on
  // Bandai (bench/notes/2026-12-02-scale-seeds.md).
  kNearestFrames,
  // The `places` nearest places to the characteristic pose, a quarter of the query's length
  // apart in a clip (LibraryIndex::NearestPlaces), one warp each: no better than the nearest
  // frames at these sizes.
  kDistinctPlaces,
  // The `neighbours` frames whose seed windows (the pose and the poses a quarter second either
  // side, LibraryIndex::NearestWindows) are nearest to the query's around the characteristic
  // frame, clustered in time as the nearest frames are.
  kNearestWindows,
  // Candidates from the query's whole shape (issue 39, item 3): the library windows
  // (LibraryIndex::NearestShapes, lengths about sqrt(2) apart from 0.5 to 5.7 s, each resampled
  // to 16 poses of the first 10 coordinates) nearest the query resampled alike, at the length
  // nearest the query's and `shape_lengths_either_side` lengths either side (a take up to twice
  // as fast or slow is still a candidate), the `shape_windows` nearest at each length; the
  // windows of the first `shape_clips` distinct clips, each widened by half the query's length
  // on both sides, are re-ranked by the exact search's subsequence warp (its bounds and early
  // abandoning) over those ranges alone, at about 15 Hz with refinement (`refine`), the best
  // coarse warps then settled at the full rate. The characteristic points and the other seed
  // parameters do not apply; a one-frame query is a pose search as ever.
  kShapeWindows,
};

// A clip's range, in frames at the library's rate, that no result may overlap: a result over
// frames a..b overlaps it when a <= last_frame and b >= first_frame. last_frame may be
// first_frame - 1, a range that falls between two library frames, which the results spanning
// that gap overlap.
struct ExcludedRange {
  int64_t clip_id = 0;
  int64_t first_frame = 0;
  int64_t last_frame = 0;
};

// The most results one search returns (max_results' upper bound).
inline constexpr int kMaxSearchResults = 10'000;
// The most characteristic points of one query.
inline constexpr int kMaxCharacteristicPoints = 16;

struct SearchParams {
  // Dimensions of the nearest-neighbour seed search (the index's kd-tree dimensions: others
  // fall back to a linear scan).
  int ann_dims = kDefaultAnnDims;
  SeedSelection seed_selection = SeedSelection::kNearestFrames;
  // kDistinctPlaces: seeds, one warp each.
  int places = 128;
  // kNearestFrames and kNearestWindows: seeds, nearest library frames to the characteristic
  // pose (or window); 0: by the library's size (frames: 1000 up to 10 hours, 2000 at 100 hours;
  // windows: 500), taken again, twice as many, while they fall in fewer than two places a
  // result (core/search/motion_search.cc).
  int neighbours = 0;
  // kShapeWindows: the nearest windows asked at each length searched, and the distinct clips,
  // nearest first, whose windows are re-ranked by the warp. On 10 h of real capture (20 queries,
  // bench/notes/2026-12-07-shape-two-rate.md) 100 and 100 gave recall@10 against the exact search
  // 0.905, 200 and 300 gave 0.995 (p50 4.7 and 6.2 ms; nearest frames 0.940, 6.6 ms); on Bandai
  // (a few hundred clips) both 0.98-1.0, 200 and 300 0.05-0.3 ms slower at the median.
  int shape_windows = 200;
  int shape_clips = 300;
  // kShapeWindows: the window lengths searched either side of the one nearest the query's
  // (sqrt(2) apart: 2 reaches half and twice the query's length, the default slope limit's).
  int shape_lengths_either_side = 2;
  // Approximation bound of the seed search (0 = exact).
  float epsilon = 0.0f;
  // Dimensions of the pose distance inside the time warp.
  int dtw_dims = kDefaultWarpDims;
  // The warp never runs more than this many times faster or slower than the query.
  int slope_limit = kDefaultSlopeLimit;
  // Results returned after overlap suppression.
  int max_results = 20;
  // The query frame (at the space rate) that every warp passes through; -1 finds it
  // automatically as the pose farthest from `neutral`.
  int characteristic_frame = -1;
  NeutralPose neutral = NeutralPose::kQueryMean;
  // Several characteristic points (thesis 7.2.3; core/search/multi_point_search.h): query frames
  // at the space rate, increasing, each the anchor of its own part of the query. A result
  // matches the parts in order, with any pause up to max_point_gap_s between adjacent ones.
  // Empty: one point (characteristic_frame), or characteristic_points found.
  std::vector<int> characteristic_frames;
  // With neither characteristic_frame nor characteristic_frames: the points found, one the pose
  // farthest from `neutral` in each of as many equal parts of the query; 1 is the thesis's one
  // point; 0 takes one per action of the query (characteristic_points.h, FindActionFrames).
  int characteristic_points = 1;
  // Several points: the most seconds of clip a result may skip between the end of one part's
  // match and the start of the next's beyond the query's own held pose between the parts (a
  // held pose longer than the query's is absorbed there, where one slope-limited warp cannot
  // absorb it).
  double max_point_gap_s = 10.0;
  // Nearest frames or windows, one characteristic point: when its seeds fall in more clusters
  // than this share of them (a pose common to many takes, so that its seeds scatter over them),
  // half of the seeds go to a second anchor, the query frame farthest from the characteristic
  // pose at least a quarter of the query away (and a row of its own at the warps' coarse rate),
  // each warp passing through its own seed's anchor. On 10 h of real capture (794 clusters from
  // 1000 seeds) recall@10 against the exact search rose from 0.85 to 0.94 (20 queries) for about
  // 0.6 ms more at the median; synthetic capture (at most 175 clusters) does not reach it, and
  // Bandai's figures are unchanged (bench/notes/2026-12-04-scale-second-anchor.md). 0: one anchor
  // always.
  double second_anchor_scatter = 0.5;
  // Seeds of one clip closer than this in time join one cluster.
  double cluster_gap_s = 0.1;
  // A result is dropped when it overlaps a better one by more than this fraction of its length.
  double max_overlap = 0.5;
  // Move each candidate to the best warp near it, free of its seed, before ranking
  // (core/warp_refinement.h): a warp pinned to a seed in a held pose can score far worse than
  // the best warp beside it. false runs the thesis's algorithm as is (kShapeWindows: re-ranks
  // at the full rate instead of about 15 Hz).
  bool refine = true;
  // Exact search: threads scanning the library's clips (0: one per core).
  int exact_threads = 0;
  // Fast search: threads sharing the query's warps and refinement (each part's, with several
  // characteristic points; the seeds are found on one; the shape stage runs on one); 0: one per
  // core. The results are the same
  // however many: each warp and settle is judged, in order, against what the ones before it left
  // (util/thread_team.h). One by default, as the thesis's algorithm: a
  // server gives a search every core only while it runs no other (server/search_runner.h).
  int threads = 1;
  // Return each result's warp path (one library frame per query frame).
  bool return_path = false;
  // Only clips with these ids (empty: all clips).
  std::vector<int64_t> clip_ids;
  // Only clips carrying at least one of these tags (empty: no tag filter).
  std::vector<std::string> tags;
  // No result overlapping this range (a stored query's own range and its near shifts, which
  // would rank first): left out inside the search, before the ranking and its overlap rule, as
  // the filters above leave clips out, so that the search runs once for max_results others.
  std::optional<ExcludedRange> excluded;
  // Polled inside long loops; returning true stops the search with CANCELLED.
  std::function<bool()> should_stop;
};

// "nearest_frames", "distinct_places", "nearest_windows" or "shape_windows".
const char* SeedSelectionName(SeedSelection selection);

// INVALID_ARGUMENT naming the first out-of-range parameter; `dims` is the library's dimensions.
absl::Status ValidateSearchParams(const SearchParams& params, int dims);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_SEARCH_PARAMS_H_
