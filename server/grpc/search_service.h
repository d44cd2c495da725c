// motiondb.v1.SearchService: query-by-example search, one query or a batch.
#ifndef MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_

#include "motiondb/v1/search_service.grpc.pb.h"
#include "server/index_registry.h"
#include "server/search_runner.h"
#include "storage/database.h"

namespace motiondb::server {

class SearchServiceImpl final : public v1::SearchService::Service {
 public:
  SearchServiceImpl(storage::Database& database, const IndexRegistry& registry,
                    const SearchLimits& limits)
      : database_(database), registry_(registry), limits_(limits) {}

  grpc::Status Search(grpc::ServerContext* context, const v1::SearchRequest* request,
                      v1::SearchResponse* response) override;
  grpc::Status SearchBatch(grpc::ServerContext* context, const v1::SearchBatchRequest* request,
                           v1::SearchBatchResponse* response) override;

 private:
  absl::Status Batch(const v1::SearchBatchRequest& request, grpc::ServerContext* context,
                     v1::SearchBatchResponse* response);

  storage::Database& database_;
  const IndexRegistry& registry_;
  SearchLimits limits_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_
