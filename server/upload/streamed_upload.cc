#include "server/upload/streamed_upload.h"

#include <utility>

#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {

StreamedUpload::StreamedUpload(std::string name, const UploadLimits& limits)
    : name_(std::move(name)), limits_(limits), reader_(UploadReadOptions(limits)) {}

absl::Status StreamedUpload::Append(absl::string_view chunk, UploadBudget::Ticket& ticket) {
  // The file's own limit first: it is final, while the budget's refusal is worth a retry.
  MOTIONDB_RETURN_IF_ERROR(Prefixed(
      name_, CheckUploadSize(reader_.bytes() + static_cast<int64_t>(chunk.size()), limits_)));
  MOTIONDB_RETURN_IF_ERROR(ticket.Reserve(static_cast<int64_t>(chunk.size())));
  return Prefixed(name_, reader_.Append(chunk));
}

absl::StatusOr<BvhReadResult> StreamedUpload::Finish() { return Prefixed(name_, reader_.Finish()); }

}  // namespace motiondb::server
