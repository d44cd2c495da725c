// One search's results over disjoint parts of a library (the logical shards of a cluster, each
// searched on its own LibraryIndex) merged into the answer of one library holding every part.
#ifndef MOTIONDB_CORE_SEARCH_MERGE_PART_RESULTS_H_
#define MOTIONDB_CORE_SEARCH_MERGE_PART_RESULTS_H_

#include <vector>

#include "core/search/search_result.h"

namespace motiondb {

// The best `max_results` of the parts' results, ranked by RanksBefore. Each part's list is its
// own ranked answer (at most `max_results`, overlaps already dropped) and every clip lies in one
// part: results of different clips never overlap, so the whole library's best are the best of
// the parts' best, and nothing more is dropped. Exact for the exact search. The results' clip
// ids must be set and unique across parts (ties go by them); their clip_index stays each part's
// own, so the merged list must not be ranked again with Overlaps, which compares indices. A
// search filtered to clips (SearchParams::clip_ids) gives each part only its own clips: a part
// refuses a clip it does not hold.
std::vector<SearchResult> MergePartResults(std::vector<std::vector<SearchResult>> parts,
                                           int max_results);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_MERGE_PART_RESULTS_H_
