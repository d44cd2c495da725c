// An uploaded file's ingest as a call makes it: its bytes admitted to the upload budget, the file
// stored (all its takes, or a routed one), counted and answered. What ClipService.IngestClip and a
// shard's ShardService.StoreTake share.
#ifndef MOTIONDB_SERVER_GRPC_INTERNAL_UPLOAD_INGEST_H_
#define MOTIONDB_SERVER_GRPC_INTERNAL_UPLOAD_INGEST_H_

#include <functional>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "motiondb/v1/clip_service.pb.h"
#include "server/catalog.h"
#include "server/clip_ingest.h"
#include "server/metrics/server_metrics.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

struct UploadIngestParts {
  Catalog& catalog;
  const UploadLimits& limits;
  UploadBudget& budget;
  ServerMetrics& metrics;
};

absl::Status IngestUploadedFile(const UploadIngestParts& parts, const IngestRequest& ingest,
                                absl::string_view bytes, const std::function<bool()>& should_stop,
                                v1::IngestClipResponse* response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_INTERNAL_UPLOAD_INGEST_H_
