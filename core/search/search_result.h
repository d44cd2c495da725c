// What a search returns: ranked time ranges of library clips, and per-stage timings and counts.
#ifndef MOTIONDB_CORE_SEARCH_SEARCH_RESULT_H_
#define MOTIONDB_CORE_SEARCH_SEARCH_RESULT_H_

#include <cstdint>
#include <string>
#include <vector>

namespace motiondb {

struct SearchResult {
  int clip_index = 0;  // in the LibraryIndex
  int64_t clip_id = 0;
  std::string clip_name;
  int64_t first_frame = 0;  // inclusive, at the space rate
  int64_t last_frame = 0;   // inclusive, at the space rate
  double start_s = 0;
  double end_s = 0;
  double score = 0;  // mean pose distance along the warp; lower is better
  // The clip frame matched to the characteristic query frame: the seed the warp was anchored
  // at, or where refinement moved it (-1 in exact mode).
  int64_t seed_frame = -1;
  std::vector<int64_t> path;  // clip frame per query frame, when requested
};

struct SearchStats {
  int characteristic_frame = -1;  // query frame at the space rate
  int64_t seeds = 0;
  int64_t clusters = 0;  // cluster representatives, each the anchor of one warp
  int64_t warps = 0;     // warps completed (inside their clip, not abandoned)
  // Exact mode: DTW cells evaluated and column blocks skipped by the lower bound; on several
  // threads they depend on which clips finish first.
  int64_t cells = 0;
  int64_t pruned_blocks = 0;
  // Milliseconds per stage; the exact mode has one stage, its warps, and leaves the others 0.
  double characteristic_ms = 0;
  double seeds_ms = 0;
  double clusters_ms = 0;
  double warps_ms = 0;  // the warps alone: anchored (fast mode) or over every clip (exact mode)
  double refine_ms = 0;
  double ranking_ms = 0;
  double total_ms = 0;  // the whole search, checking the query included: at least the stages' sum
};

struct SearchResponse {
  std::vector<SearchResult> results;
  SearchStats stats;
};

// True when `a` overlaps `b` (same clip) by more than `max_overlap` of a's length.
bool Overlaps(const SearchResult& a, const SearchResult& b, double max_overlap);

// Sorts by score (then clip and frame, for determinism), drops every result that overlaps a
// better kept one by more than `max_overlap` of its length, and keeps at most `max_results`.
std::vector<SearchResult> RankResults(std::vector<SearchResult> candidates, double max_overlap,
                                      int max_results);

// The best `k` non-overlapping results seen so far, kept greedily as candidates stream in, and
// the cost a partial warp must stay below to still have a chance (early abandoning).
// Not thread-safe: one per search.
class StreamingTopResults {
 public:
  StreamingTopResults(int k, double max_overlap, int64_t query_rows)
      : k_(k), max_overlap_(max_overlap), query_rows_(query_rows) {}

  void Offer(SearchResult candidate);
  // Warp costs (sums over the query's frames) at or above this cannot enter the kept set.
  float threshold() const;
  std::vector<SearchResult> Take() { return std::move(kept_); }

 private:
  double worst_score() const;

  int k_;
  double max_overlap_;
  int64_t query_rows_;
  std::vector<SearchResult> kept_;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_SEARCH_RESULT_H_
