// SearchService's messages and the application's search types (server/search_runner.h), both
// ways. Only what a request sets replaces SearchParams' defaults; INVALID_ARGUMENT names the
// field for what no struct can hold (an unknown enum value).
#ifndef MOTIONDB_SERVER_GRPC_SEARCH_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_SEARCH_CONVERSION_H_

#include "absl/status/statusor.h"
#include "motiondb/v1/search_service.pb.h"
#include "server/search_explanation.h"
#include "server/search_runner.h"

namespace motiondb::server {

absl::StatusOr<SearchRequest> FromProto(const v1::SearchRequest& request);

void ToProto(const SearchExplanation& explanation, v1::SearchExplanation* out);
void ToProto(const SearchOutcome& outcome, v1::SearchResponse* response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SEARCH_CONVERSION_H_
