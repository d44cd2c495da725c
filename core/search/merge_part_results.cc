#include "core/search/merge_part_results.h"

#include <algorithm>
#include <iterator>
#include <utility>

namespace motiondb {

std::vector<SearchResult> MergePartResults(std::vector<std::vector<SearchResult>> parts,
                                           int max_results) {
  std::vector<SearchResult> merged;
  for (std::vector<SearchResult>& part : parts) {
    std::move(part.begin(), part.end(), std::back_inserter(merged));
  }
  const size_t kept = std::min(merged.size(), static_cast<size_t>(std::max(max_results, 0)));
  std::partial_sort(merged.begin(), merged.begin() + static_cast<std::ptrdiff_t>(kept),
                    merged.end(), RanksBefore);
  merged.resize(kept);
  return merged;
}

}  // namespace motiondb
