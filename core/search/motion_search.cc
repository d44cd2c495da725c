#include "core/search/motion_search.h"

#include <chrono>
#include <vector>

#include "core/search/characteristic_points.h"
#include "core/search/internal/multi_point_search.h"
#include "core/search/internal/pose_search.h"
#include "core/search/internal/search_query.h"
#include "core/search/internal/shape_search.h"
#include "core/search/internal/single_point_search.h"
#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<SearchResponse> Search(const LibraryIndex& library, CoordinateView query,
                                      const SearchParams& params) {
  const auto start = std::chrono::steady_clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const SearchFilter filter, PrepareQuery(library, query, params));
  if (query.rows == 1) return PoseSearch(library, query, filter, params);
  if (params.seed_selection == SeedSelection::kShapeWindows) {
    return ShapeSearch(library, query, filter, params);
  }
  const std::vector<int> anchors = CharacteristicFrames(query, library.rate(), params);
  const double characteristic_ms = MillisecondsSince(start);
  MOTIONDB_ASSIGN_OR_RETURN(
      SearchResponse response,
      anchors.size() > 1 ? MultiPointSearch(library, query, anchors, filter, params)
                         : SinglePointSearch(library, query, anchors.front(), filter, params));
  response.stats.characteristic_ms += characteristic_ms;
  response.stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
