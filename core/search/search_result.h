// What a search returns: ranked time ranges of library clips, and per-stage timings and counts.
#ifndef MOTIONDB_CORE_SEARCH_SEARCH_RESULT_H_
#define MOTIONDB_CORE_SEARCH_SEARCH_RESULT_H_

#include <cstdint>
#include <limits>
#include <string>
#include <utility>
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
  // The clip frame matched to the characteristic query frame (the first of several): the seed
  // the warp was anchored at, or where refinement moved it, or, for a warp through a second
  // anchor's seed (SearchParams::second_anchor_scatter), where its path passes that frame (-1
  // in exact mode).
  int64_t seed_frame = -1;
  std::vector<int64_t> path;  // clip frame per query frame, when requested
};

struct SearchStats {
  int characteristic_frame = -1;           // query frame at the space rate (the first of several)
  std::vector<int> characteristic_frames;  // every point used, at the space rate, in order
  // The query frame of SearchParams::second_anchor_scatter's second anchor, at the space rate;
  // -1 when there was none.
  int second_anchor = -1;
  int64_t seeds = 0;
  int64_t clusters = 0;  // cluster representatives, each the anchor of one warp
  // Warps completed (inside their clip, not abandoned); on several threads, some warped against
  // an older threshold than one thread's count too.
  int64_t warps = 0;
  int threads = 1;  // the threads of the warps and refinement (SearchParams::threads)
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

// Adds `part`'s counts and stage times to `total`, for a search made of several searches (the
// parts of a several-point query, the halves of a mirrored one). `threads` and `total_ms` are
// the caller's: the parts ran one after another.
void AddStageStats(const SearchStats& part, SearchStats& total);

struct SearchResponse {
  std::vector<SearchResult> results;
  SearchStats stats;
};

// True when `a` overlaps `b` (same clip) by more than `max_overlap` of a's length.
bool Overlaps(const SearchResult& a, const SearchResult& b, double max_overlap);

// The ranking order: by score, equal scores by clip id (then index, for results without ids),
// end frame and start frame (the order in which a clip's scan, ExactSearch, meets its warps).
// Ties go by clip id, not by where a clip sits in a library, so that libraries holding the same
// clips in another order, or split in parts (the shards of a cluster, MergePartResults), rank
// alike: an exact copy of a take ranks the same wherever it is. StreamingTopResults and
// RankResults keep the same results only because they break ties alike.
bool RanksBefore(const SearchResult& a, const SearchResult& b);

// Sorts by RanksBefore, drops every result that overlaps a better kept one by more than
// `max_overlap` of its length, and keeps at most `max_results`.
std::vector<SearchResult> RankResults(std::vector<SearchResult> candidates, double max_overlap,
                                      int max_results);
// The indices of the candidates RankResults would keep, in its order, the candidates left as
// they are (for a caller that knows more of each candidate than its result).
std::vector<size_t> RankedIndices(const std::vector<SearchResult>& candidates, double max_overlap,
                                  int max_results);
// How many results RankResults would keep, the candidates left as they are.
int RankedCount(const std::vector<SearchResult>& candidates, double max_overlap, int max_results);

// The best `k` non-overlapping results seen so far, kept greedily as candidates stream in, and
// the cost a partial warp must stay below to still have a chance (early abandoning). A fast
// search offers each of its ~1000 warps to a pool of up to ~1200 (max_results 100): the kept
// results are grouped by clip, so that an offer compares only its clip's (results of different
// clips never overlap), and the worst kept score is cached.
// Not thread-safe: one per search.
class StreamingTopResults {
 public:
  StreamingTopResults(int k, double max_overlap, int64_t query_rows)
      : k_(k), max_overlap_(max_overlap), query_rows_(query_rows) {}

  void Offer(SearchResult candidate);
  // Warp costs (sums over the query's frames) at or above this cannot enter the kept set.
  float threshold() const;
  // The kept results in the order they were offered; the set is empty afterwards.
  std::vector<SearchResult> Take();

 private:
  struct Kept {
    SearchResult result;
    int64_t offered = 0;  // the offer's number: Take's order
  };
  // The kept result that ranks last (RanksBefore).
  std::pair<int, size_t> FindWorst() const;  // (clip index, position in its group)
  double worst_score() const;

  int k_;
  double max_overlap_;
  int64_t query_rows_;
  std::vector<std::vector<Kept>> by_clip_;  // by clip index
  // The clips whose group has held a result, each once: what FindWorst and Take scan (a library
  // of 8,175 clips has a few hundred).
  std::vector<int> held_;
  int kept_count_ = 0;
  int64_t offers_ = 0;
  // worst_score()'s value while kept_count_ is unchanged and full, or NaN.
  mutable double worst_score_cache_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_SEARCH_RESULT_H_
