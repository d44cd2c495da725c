#include "server/grpc/internal/upload_ingest.h"

#include "server/grpc/clip_conversion.h"
#include "util/status_macros.h"

namespace motiondb::server {

absl::Status IngestUploadedFile(const UploadIngestParts& parts, const IngestRequest& ingest,
                                absl::string_view bytes, const std::function<bool()>& should_stop,
                                v1::IngestClipResponse* response) {
  MOTIONDB_ASSIGN_OR_RETURN(UploadBudget::Ticket ticket, parts.budget.Admit());
  MOTIONDB_RETURN_IF_ERROR(ticket.Reserve(static_cast<int64_t>(bytes.size())));
  MOTIONDB_ASSIGN_OR_RETURN(const IngestedFile ingested,
                            IngestUpload(parts.catalog, ingest, bytes, parts.limits, should_stop));
  for (const IngestOutcome& outcome : ingested.clips) parts.metrics.CountIngest(outcome);
  ToProto(ingested, response);
  return absl::OkStatus();
}

}  // namespace motiondb::server
