#include "server/grpc/search_service.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "server/grpc/search_conversion.h"
#include "server/grpc/serve.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

constexpr int kMaxBatch = 1000;

}  // namespace

absl::StatusOr<v1::SearchResponse> SearchServiceImpl::SearchOne(
    const v1::SearchRequest& request, const std::function<bool()>& should_stop,
    int64_t* answers_used) const {
  MOTIONDB_ASSIGN_OR_RETURN(SearchRequest search, FromProto(request));
  search.answers = &answers_;
  search.answers_used = *answers_used;
  MOTIONDB_ASSIGN_OR_RETURN(const SearchOutcome outcome, runner_.Run(search, should_stop));
  *answers_used += outcome.answer_bytes;
  metrics_.CountSearch(outcome);
  v1::SearchResponse response;
  ToProto(outcome, &response);
  return response;
}

grpc::Status SearchServiceImpl::Search(grpc::ServerContext* context,
                                       const v1::SearchRequest* request,
                                       v1::SearchResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    int64_t answers_used = 0;
    MOTIONDB_ASSIGN_OR_RETURN(*response, SearchOne(*request, should_stop, &answers_used));
    return absl::OkStatus();
  });
}

absl::Status SearchServiceImpl::Batch(const v1::SearchBatchRequest& request,
                                      const std::function<bool()>& should_stop,
                                      v1::SearchBatchResponse* response) {
  if (request.requests_size() > kMaxBatch) {
    return absl::InvalidArgumentError(absl::StrCat("requests: ", request.requests_size(),
                                                   " searches; at most ", kMaxBatch, " per batch"));
  }
  // The items' answers share the answer limit: each is checked with those before it.
  int64_t answers_used = 0;
  for (int i = 0; i < request.requests_size(); ++i) {
    if (should_stop()) return absl::CancelledError(absl::StrCat("before requests[", i, "]"));
    absl::StatusOr<v1::SearchResponse> found =
        SearchOne(request.requests(i), should_stop, &answers_used);
    // A stop ends the whole batch; any other failure belongs to its item alone.
    if (absl::IsCancelled(found.status())) return found.status();
    v1::SearchBatchItem* item = response->add_items();
    if (found.ok()) {
      *item->mutable_response() = *std::move(found);
    } else {
      item->set_code(static_cast<int>(found.status().code()));
      item->set_message(absl::StrCat("requests[", i, "]: ", found.status().message()));
      answers_used += TextFieldBytes(static_cast<int64_t>(item->message().size())) +
                      kNumberFieldBytes + kFieldFramingBytes;
    }
  }
  return absl::OkStatus();
}

grpc::Status SearchServiceImpl::SearchBatch(grpc::ServerContext* context,
                                            const v1::SearchBatchRequest* request,
                                            v1::SearchBatchResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) {
    return Batch(*request, should_stop, response);
  });
}

}  // namespace motiondb::server
