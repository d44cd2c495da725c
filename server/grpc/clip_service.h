// motiondb.v1.ClipService: ingest, list, get, update, delete and export clips, and their poses;
// list, show and map skeletons.
#ifndef MOTIONDB_SERVER_GRPC_CLIP_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_CLIP_SERVICE_H_

#include <functional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "server/answer_limit.h"
#include "server/catalog.h"
#include "server/clip_ingest.h"
#include "server/grpc/call_gate.h"
#include "server/grpc/stream_upload.h"
#include "server/grpc/stream_watchdog.h"
#include "server/metrics/server_metrics.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"
#include "storage/database.h"

namespace motiondb::server {

class ClipServiceImpl final : public v1::ClipService::Service {
 public:
  // `budget` and `watchdog` bound the ingests in progress (server/upload/upload_budget.h,
  // server/grpc/stream_watchdog.h); `answers` the exports and poses.
  ClipServiceImpl(storage::Database& database, Catalog& catalog, const UploadLimits& limits,
                  const AnswerLimit& answers, UploadBudget& budget, StreamWatchdog& watchdog,
                  ServerMetrics& metrics, CallGate& gate)
      : database_(database),
        catalog_(catalog),
        limits_(limits),
        answers_(answers),
        budget_(budget),
        watchdog_(watchdog),
        metrics_(metrics),
        gate_(gate) {}

  grpc::Status IngestClip(grpc::ServerContext* context, const v1::IngestClipRequest* request,
                          v1::IngestClipResponse* response) override;
  grpc::Status IngestClipStream(grpc::ServerContext* context,
                                grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
                                v1::IngestClipResponse* response) override;
  grpc::Status ListClips(grpc::ServerContext* context, const v1::ListClipsRequest* request,
                         v1::ListClipsResponse* response) override;
  grpc::Status GetClip(grpc::ServerContext* context, const v1::GetClipRequest* request,
                       v1::Clip* response) override;
  grpc::Status DeleteClip(grpc::ServerContext* context, const v1::DeleteClipRequest* request,
                          v1::DeleteClipResponse* response) override;
  grpc::Status UpdateClip(grpc::ServerContext* context, const v1::UpdateClipRequest* request,
                          v1::Clip* response) override;
  grpc::Status ExportClip(grpc::ServerContext* context, const v1::ExportClipRequest* request,
                          v1::ExportClipResponse* response) override;
  grpc::Status ExportClipStream(grpc::ServerContext* context, const v1::ExportClipRequest* request,
                                grpc::ServerWriter<v1::ExportClipResponse>* writer) override;
  grpc::Status GetClipPoses(grpc::ServerContext* context, const v1::GetClipPosesRequest* request,
                            v1::ClipPoses* response) override;
  grpc::Status ListSkeletons(grpc::ServerContext* context, const v1::ListSkeletonsRequest* request,
                             v1::ListSkeletonsResponse* response) override;
  grpc::Status GetSkeleton(grpc::ServerContext* context, const v1::GetSkeletonRequest* request,
                           v1::SkeletonDetail* response) override;
  grpc::Status MapSkeleton(grpc::ServerContext* context, const v1::MapSkeletonRequest* request,
                           v1::SkeletonDetail* response) override;

 private:
  // An IngestClipStream's file as it arrived, with its share of the upload budget.
  struct ReadUpload {
    UploadBudget::Ticket ticket;
    ReceivedUpload upload;
  };
  absl::StatusOr<ReadUpload> ReadStream(grpc::ServerContext* context,
                                        grpc::ServerReader<v1::IngestClipStreamRequest>* reader);
  absl::Status IngestStreamed(ReadUpload read, const std::function<bool()>& should_stop,
                              v1::IngestClipResponse* response);

  storage::Database& database_;
  Catalog& catalog_;
  UploadLimits limits_;
  AnswerLimit answers_;
  UploadBudget& budget_;
  StreamWatchdog& watchdog_;
  ServerMetrics& metrics_;
  CallGate& gate_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_CLIP_SERVICE_H_
