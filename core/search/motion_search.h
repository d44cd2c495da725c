// Query-by-example search in a library (thesis chapter 6): a query of one frame is a pose query
// (pose_search.h), one with one characteristic point the thesis's search
// (internal/single_point_search.h), one with several a search through each
// (internal/multi_point_search.h).
#ifndef MOTIONDB_CORE_SEARCH_MOTION_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_MOTION_SEARCH_H_

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// `query`: the query's projection at the library's rate, pre-scaled like the library, with the
// library's dimensions; a query of one frame is a pose query (pose_search.h), one with several
// characteristic points a multi-point search (multi_point_search.h). Thread-safe: any number of
// searches may run on one library at once.
absl::StatusOr<SearchResponse> Search(const LibraryIndex& library, CoordinateView query,
                                      const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_MOTION_SEARCH_H_
