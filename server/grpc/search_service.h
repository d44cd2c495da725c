// motiondb.v1.SearchService: query-by-example search, one query or a batch.
#ifndef MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_

#include <functional>

#include "absl/status/statusor.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "server/grpc/call_gate.h"
#include "server/search_runner.h"
#include "server/server_metrics.h"

namespace motiondb::server {

class SearchServiceImpl final : public v1::SearchService::Service {
 public:
  SearchServiceImpl(const SearchRunner& runner, ServerMetrics& metrics, CallGate& gate)
      : runner_(runner), metrics_(metrics), gate_(gate) {}

  grpc::Status Search(grpc::ServerContext* context, const v1::SearchRequest* request,
                      v1::SearchResponse* response) override;
  grpc::Status SearchBatch(grpc::ServerContext* context, const v1::SearchBatchRequest* request,
                           v1::SearchBatchResponse* response) override;

 private:
  absl::Status Batch(const v1::SearchBatchRequest& request, grpc::ServerContext* context,
                     v1::SearchBatchResponse* response);

  // One search through the runner, as the response message.
  absl::StatusOr<v1::SearchResponse> SearchOne(const v1::SearchRequest& request,
                                               const std::function<bool()>& should_stop) const;

  const SearchRunner& runner_;
  ServerMetrics& metrics_;
  CallGate& gate_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_
