#include "core/search/search_result.h"

#include <algorithm>
#include <limits>
#include <tuple>

namespace motiondb {

bool Overlaps(const SearchResult& a, const SearchResult& b, double max_overlap) {
  if (a.clip_index != b.clip_index) return false;
  const int64_t overlap =
      std::min(a.last_frame, b.last_frame) - std::max(a.first_frame, b.first_frame) + 1;
  return overlap > max_overlap * static_cast<double>(a.last_frame - a.first_frame + 1);
}

std::vector<SearchResult> RankResults(std::vector<SearchResult> candidates, double max_overlap,
                                      int max_results) {
  std::sort(candidates.begin(), candidates.end(), [](const SearchResult& a, const SearchResult& b) {
    return std::tie(a.score, a.clip_index, a.first_frame) <
           std::tie(b.score, b.clip_index, b.first_frame);
  });
  std::vector<SearchResult> kept;
  for (SearchResult& candidate : candidates) {
    if (static_cast<int>(kept.size()) == max_results) break;
    const bool suppressed = std::any_of(kept.begin(), kept.end(), [&](const SearchResult& better) {
      return Overlaps(candidate, better, max_overlap);
    });
    if (!suppressed) kept.push_back(std::move(candidate));
  }
  return kept;
}

namespace {

bool ByScore(const SearchResult& a, const SearchResult& b) { return a.score < b.score; }

}  // namespace

void StreamingTopResults::Offer(SearchResult candidate) {
  if (static_cast<int>(kept_.size()) == k_ && candidate.score >= worst_score()) return;
  for (const SearchResult& kept : kept_) {
    if (kept.score <= candidate.score && Overlaps(candidate, kept, max_overlap_)) return;
  }
  std::erase_if(kept_, [&](const SearchResult& kept) {
    return kept.score > candidate.score && Overlaps(kept, candidate, max_overlap_);
  });
  kept_.push_back(std::move(candidate));
  if (static_cast<int>(kept_.size()) > k_) {
    kept_.erase(std::max_element(kept_.begin(), kept_.end(), ByScore));
  }
}

float StreamingTopResults::threshold() const {
  if (static_cast<int>(kept_.size()) < k_) return std::numeric_limits<float>::infinity();
  return static_cast<float>(worst_score() * static_cast<double>(query_rows_));
}

double StreamingTopResults::worst_score() const {
  return std::max_element(kept_.begin(), kept_.end(), ByScore)->score;
}

}  // namespace motiondb
