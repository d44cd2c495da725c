#include "core/search/search_result.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <tuple>

namespace motiondb {

void AddStageStats(const SearchStats& part, SearchStats& total) {
  total.seeds += part.seeds;
  total.clusters += part.clusters;
  total.warps += part.warps;
  total.cells += part.cells;
  total.pruned_blocks += part.pruned_blocks;
  total.characteristic_ms += part.characteristic_ms;
  total.seeds_ms += part.seeds_ms;
  total.clusters_ms += part.clusters_ms;
  total.warps_ms += part.warps_ms;
  total.refine_ms += part.refine_ms;
  total.ranking_ms += part.ranking_ms;
}

bool Overlaps(const SearchResult& a, const SearchResult& b, double max_overlap) {
  if (a.clip_index != b.clip_index) return false;
  const int64_t overlap =
      std::min(a.last_frame, b.last_frame) - std::max(a.first_frame, b.first_frame) + 1;
  return overlap > max_overlap * static_cast<double>(a.last_frame - a.first_frame + 1);
}

bool RanksBefore(const SearchResult& a, const SearchResult& b) {
  return std::tie(a.score, a.clip_id, a.clip_index, a.last_frame, a.first_frame) <
         std::tie(b.score, b.clip_id, b.clip_index, b.last_frame, b.first_frame);
}

std::vector<size_t> RankedIndices(const std::vector<SearchResult>& candidates, double max_overlap,
                                  int max_results) {
  std::vector<size_t> order(candidates.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t i, size_t j) { return RanksBefore(candidates[i], candidates[j]); });
  std::vector<size_t> kept;
  for (size_t i : order) {
    if (static_cast<int>(kept.size()) == max_results) break;
    const bool suppressed = std::any_of(kept.begin(), kept.end(), [&](size_t better) {
      return Overlaps(candidates[i], candidates[better], max_overlap);
    });
    if (!suppressed) kept.push_back(i);
  }
  return kept;
}

std::vector<SearchResult> RankResults(std::vector<SearchResult> candidates, double max_overlap,
                                      int max_results) {
  std::vector<SearchResult> kept;
  for (size_t i : RankedIndices(candidates, max_overlap, max_results)) {
    kept.push_back(std::move(candidates[i]));
  }
  return kept;
}

int RankedCount(const std::vector<SearchResult>& candidates, double max_overlap, int max_results) {
  return static_cast<int>(RankedIndices(candidates, max_overlap, max_results).size());
}

void StreamingTopResults::Offer(SearchResult candidate) {
  if (kept_count_ == k_ && candidate.score > worst_score()) return;
  if (static_cast<int>(by_clip_.size()) <= candidate.clip_index) {
    by_clip_.resize(candidate.clip_index + 1);
  }
  std::vector<Kept>& group = by_clip_[candidate.clip_index];
  // A group that has never held a result has never allocated.
  if (group.capacity() == 0) held_.push_back(candidate.clip_index);
  // Kept and dropped as RankResults would rank them, so that it keeps every kept one.
  for (const Kept& kept : group) {
    // (An equal one, which ranks neither before nor after, suppresses it too, as it would there.)
    if (!RanksBefore(candidate, kept.result) && Overlaps(candidate, kept.result, max_overlap_)) {
      return;
    }
  }
  kept_count_ -= static_cast<int>(std::erase_if(group, [&](const Kept& kept) {
    return RanksBefore(candidate, kept.result) && Overlaps(kept.result, candidate, max_overlap_);
  }));
  group.push_back({std::move(candidate), offers_++});
  ++kept_count_;
  if (kept_count_ > k_) {
    const auto [clip, position] = FindWorst();
    by_clip_[clip].erase(by_clip_[clip].begin() + static_cast<std::ptrdiff_t>(position));
    --kept_count_;
  }
  worst_score_cache_ = std::numeric_limits<double>::quiet_NaN();
}

float StreamingTopResults::threshold() const {
  if (kept_count_ < k_) return std::numeric_limits<float>::infinity();
  return static_cast<float>(worst_score() * static_cast<double>(query_rows_));
}

std::vector<SearchResult> StreamingTopResults::Take() {
  std::vector<Kept> all;
  all.reserve(kept_count_);
  for (const int clip : held_) {
    std::move(by_clip_[clip].begin(), by_clip_[clip].end(), std::back_inserter(all));
  }
  std::sort(all.begin(), all.end(),
            [](const Kept& a, const Kept& b) { return a.offered < b.offered; });
  std::vector<SearchResult> results;
  results.reserve(all.size());
  for (Kept& kept : all) results.push_back(std::move(kept.result));
  // by_clip_ keeps its size: a set reused for many short scans (the shape search's ranges) of a
  // library of thousands of clips would otherwise build it again for each.
  for (const int clip : held_) by_clip_[clip] = std::vector<Kept>();  // capacity 0: unheld
  held_.clear();
  kept_count_ = 0;
  worst_score_cache_ = std::numeric_limits<double>::quiet_NaN();
  return results;
}

std::pair<int, size_t> StreamingTopResults::FindWorst() const {
  std::pair<int, size_t> worst{-1, 0};
  const Kept* worst_kept = nullptr;
  for (const int c : held_) {
    for (size_t i = 0; i < by_clip_[c].size(); ++i) {
      const Kept& kept = by_clip_[c][i];
      if (worst_kept == nullptr || RanksBefore(worst_kept->result, kept.result)) {
        worst_kept = &kept;
        worst = {c, i};
      }
    }
  }
  return worst;
}

double StreamingTopResults::worst_score() const {
  if (std::isnan(worst_score_cache_)) {
    const auto [clip, position] = FindWorst();
    worst_score_cache_ = by_clip_[clip][position].result.score;
  }
  return worst_score_cache_;
}

}  // namespace motiondb
