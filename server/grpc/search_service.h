// motiondb.v1.SearchService: query-by-example search, one query or a batch.
#ifndef MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_

#include <functional>

#include "absl/status/statusor.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "server/answer_limit.h"
#include "server/grpc/call_gate.h"
#include "server/metrics/server_metrics.h"
#include "server/search_runner.h"

namespace motiondb::server {

class SearchServiceImpl final : public v1::SearchService::Service {
 public:
  SearchServiceImpl(const SearchRunner& runner, const AnswerLimit& answers, ServerMetrics& metrics,
                    CallGate& gate)
      : runner_(runner), answers_(answers), metrics_(metrics), gate_(gate) {}

  grpc::Status Search(grpc::ServerContext* context, const v1::SearchRequest* request,
                      v1::SearchResponse* response) override;
  grpc::Status SearchBatch(grpc::ServerContext* context, const v1::SearchBatchRequest* request,
                           v1::SearchBatchResponse* response) override;

 private:
  absl::Status Batch(const v1::SearchBatchRequest& request,
                     const std::function<bool()>& should_stop, v1::SearchBatchResponse* response);

  // One search through the runner, as the response message, its answer checked with the
  // `answers_used` before it (a batch's), which its own then joins.
  absl::StatusOr<v1::SearchResponse> SearchOne(const v1::SearchRequest& request,
                                               const std::function<bool()>& should_stop,
                                               int64_t* answers_used) const;

  const SearchRunner& runner_;
  AnswerLimit answers_;
  ServerMetrics& metrics_;
  CallGate& gate_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SEARCH_SERVICE_H_
