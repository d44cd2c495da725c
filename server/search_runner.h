// One search, from request message to response message: the query's coordinates (rows of a
// stored clip's cached projection, or an uploaded BVH projected on the spot), the parameters
// with the thesis's defaults for what is unset, and the results with frame numbers converted
// back to each clip's own rate.
#ifndef MOTIONDB_SERVER_SEARCH_RUNNER_H_
#define MOTIONDB_SERVER_SEARCH_RUNNER_H_

#include <cstdint>
#include <functional>

#include "absl/status/statusor.h"
#include "motiondb/v1/search_service.pb.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

struct SearchLimits {
  int64_t max_bvh_bytes = int64_t{1} << 30;  // for uploaded queries
};

// Runs `request` against the space it names. `should_stop` ends the search with CANCELLED.
absl::StatusOr<v1::SearchResponse> RunSearch(const v1::SearchRequest& request,
                                             const IndexRegistry& registry,
                                             storage::Database& database,
                                             const SearchLimits& limits,
                                             const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SEARCH_RUNNER_H_
