#include "core/search/internal/settle_best.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "absl/container/flat_hash_map.h"
#include "core/search/internal/search_query.h"
#include "core/search/warp_refinement.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// A score that no candidate above it can rank with among the max_results best of the
// candidates seen, nor of any more to come: the k-th least of the clips' best scores. Each
// clip's best is ranked whatever else overlaps it (ranking keeps the best of each clip, as one
// clip's results never overlap another's), so the k-th ranked score is at most this, and more
// candidates only lower it. (The k-th ranked score itself can rise with a new candidate that
// suppresses two others.) The full-rate settles abandon their bands over it, which is not
// exact (RefineFromCoarse): over a run of the benchmark on 10 h of real capture, 42 of 19,000
// settles were given up that would have settled under it (within 4% of it: the tail of the
// results), at 100 h 3 of 32,000; recall@10 and the result counts the same in every scenario
// (bench/notes/2026-12-04-scale-settle-bound.md), for settles that cost half as much.
class ClipBestScores {
 public:
  explicit ClipBestScores(int k) : k_(k) {}
  double bound() const { return bound_; }
  void Add(int clip, double score) {
    if (score >= bound_) return;
    const auto [it, inserted] = best_.try_emplace(clip, score);
    if (!inserted) it->second = std::min(it->second, score);
    if (static_cast<int>(best_.size()) < k_) return;
    scores_.clear();
    for (const auto& [c, s] : best_) scores_.push_back(s);
    std::nth_element(scores_.begin(), scores_.begin() + (k_ - 1), scores_.end());
    bound_ = scores_[k_ - 1];
  }

 private:
  const int k_;
  double bound_ = std::numeric_limits<double>::infinity();
  absl::flat_hash_map<int, double> best_;
  std::vector<double> scores_;
};

}  // namespace

absl::StatusOr<std::vector<SearchResult>> SettleBest(
    const LibraryIndex& library, CoordinateView query, int anchor, int factor,
    const WarpConstraints& constraints, const SearchParams& params, const SearchFilter& filter,
    std::vector<SearchResult> candidates, size_t fine_pool, ThreadTeam& team,
    std::vector<MemberState>& members) {
  const int pool = static_cast<int>(candidates.size());
  candidates = RankResults(std::move(candidates), params.max_overlap, pool);
  // Settled candidates can converge on one place (70 s at 120 Hz: 19.9 results of 20 on
  // average, the exact search 20), so while the settled hold fewer than max_results distinct
  // places, the next best candidates are settled too.
  std::vector<SearchResult> settled;
  ClipBestScores ranked_above(params.max_results);
  struct SettleAttempt {
    SearchResult candidate;  // settled, or as it was
    bool settled = false;
    double abandon_score = 0;  // the bound it was settled against
  };
  std::vector<SettleAttempt> attempts(candidates.size());
  const auto settle = [&](size_t i, double abandon_score, MemberState& member) {
    SettleAttempt& attempt = attempts[i];
    if (member.stop.Done(query.rows)) return SearchStopped();
    attempt.candidate = candidates[i];
    attempt.abandon_score = abandon_score;
    attempt.settled = RefineFromCoarse(
        query, library.clip_coordinates(attempt.candidate.clip_index), anchor, factor, constraints,
        abandon_score, member.bands, attempt.candidate, &member.stop);
    return member.stop.stopped() ? SearchStopped() : absl::OkStatus();
  };
  // A band can move a warp into the excluded range: such a settle is not kept.
  const auto keep = [&](size_t i) {
    SettleAttempt& attempt = attempts[i];
    if (!attempt.settled || !filter.Admits(attempt.candidate)) return;
    ranked_above.Add(attempt.candidate.clip_index, attempt.candidate.score);
    settled.push_back(std::move(attempt.candidate));
  };
  // The bound only falls as settles are kept, so a settle given up against an older bound is
  // given up against today's too; one kept against an older bound is settled again.
  std::atomic<double> bound{ranked_above.bound()};
  const size_t always_settled = std::min(fine_pool, candidates.size());
  MOTIONDB_RETURN_IF_ERROR(team.ParallelForInOrder(
      static_cast<int64_t>(always_settled),
      [&](int64_t i, int m) { return settle(i, bound.load(), members[m]); },
      [&](int64_t i, int m) -> absl::Status {
        if (attempts[i].settled && attempts[i].abandon_score > ranked_above.bound()) {
          MOTIONDB_RETURN_IF_ERROR(settle(i, ranked_above.bound(), members[m]));
        }
        keep(i);
        bound = ranked_above.bound();
        return absl::OkStatus();
      }));
  for (size_t i = always_settled; i < candidates.size(); ++i) {
    // A finite bound means max_results clips hold a settled result, each of them ranked.
    if (std::isfinite(ranked_above.bound()) ||
        RankedCount(settled, params.max_overlap, params.max_results) == params.max_results) {
      break;
    }
    MOTIONDB_RETURN_IF_ERROR(settle(i, ranked_above.bound(), members[0]));
    keep(i);
  }
  return settled;
}

}  // namespace motiondb
