#include "server/grpc/clip_service.h"

#include <string>
#include <utility>
#include <vector>

#include "server/clip_export.h"
#include "server/clip_ingest.h"
#include "server/clip_poses.h"
#include "server/grpc/call_context.h"
#include "server/grpc/clip_conversion.h"
#include "server/grpc/internal/upload_ingest.h"
#include "server/grpc/serve.h"
#include "server/grpc/status_conversion.h"
#include "server/grpc/stream_upload.h"
#include "server/listing.h"
#include "server/skeleton_map.h"
#include "util/status_macros.h"

namespace motiondb::server {

grpc::Status ClipServiceImpl::IngestClip(grpc::ServerContext* context,
                                         const v1::IngestClipRequest* request,
                                         v1::IngestClipResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const IngestRequest ingest, FromProto(*request));
    return IngestUploadedFile({catalog_, limits_, budget_, metrics_}, ingest, request->bvh(),
                              should_stop, response);
  });
}

absl::StatusOr<ClipServiceImpl::ReadUpload> ClipServiceImpl::ReadStream(
    grpc::ServerContext* context, grpc::ServerReader<v1::IngestClipStreamRequest>* reader) {
  // Admitted before the first message, which an idle client may never send: the watchdog ends
  // such a stream, and one that crawls, and frees its place.
  MOTIONDB_ASSIGN_OR_RETURN(UploadBudget::Ticket ticket, budget_.Admit());
  absl::StatusOr<ReceivedUpload> received;
  {
    // Only while reading: the ingest that follows may take long without a byte arriving.
    StreamWatchdog::Watch watch = watchdog_.Start(context);
    received = ReceiveUpload(*reader, watch, limits_, ticket);
  }
  MOTIONDB_ASSIGN_OR_RETURN(ReceivedUpload upload, std::move(received));
  return ReadUpload{std::move(ticket), std::move(upload)};
}

absl::Status ClipServiceImpl::IngestStreamed(ReadUpload read, const ShouldStop& should_stop,
                                             v1::IngestClipResponse* response) {
  // Read() also ends when the call is cancelled or its deadline passes: what arrived is then a
  // part of the file, which may well parse (cut at a row) and must not be stored as the clip.
  if (should_stop()) return absl::CancelledError("the upload ended before its last chunk");
  MOTIONDB_ASSIGN_OR_RETURN(UploadedFile parsed, read.upload.bvh.Finish(should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(
      const IngestedFile ingested,
      IngestParsedUpload(catalog_, read.upload.request, std::move(parsed), should_stop));
  for (const IngestOutcome& outcome : ingested.clips) metrics_.CountIngest(outcome);
  ToProto(ingested, response);
  return absl::OkStatus();
}

grpc::Status ClipServiceImpl::IngestClipStream(
    grpc::ServerContext* context, grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
    v1::IngestClipResponse* response) {
  // The caller's right first: nothing is read for one who may not ingest. The stream is then
  // read without a place among --threads (a client slow to send must not keep other calls
  // out: 8 idle streams once locked a --threads 4 server out); the ingest takes one.
  if (grpc::Status allowed = gate_.Allowed(context); !allowed.ok()) return allowed;
  absl::StatusOr<ReadUpload> read = ReadStream(context, reader);
  if (!read.ok()) return ToGrpcStatus(ExplainStop(read.status(), context));
  return Serve(gate_, context, [&](const ShouldStop& should_stop) {
    return IngestStreamed(*std::move(read), should_stop, response);
  });
}

grpc::Status ClipServiceImpl::ListClips(grpc::ServerContext* context,
                                        const v1::ListClipsRequest* request,
                                        v1::ListClipsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipPage page,
                              server::ListClips(database_, FromProto(*request), answers_));
    ToProto(page, response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::GetClipPoses(grpc::ServerContext* context,
                                           const v1::GetClipPosesRequest* request,
                                           v1::ClipPoses* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const ClipPoses poses,
                              ReadClipPoses(database_, FromProto(*request), answers_));
    ToProto(poses, response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::ListSkeletons(grpc::ServerContext* context,
                                            const v1::ListSkeletonsRequest* /*request*/,
                                            v1::ListSkeletonsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<storage::SkeletonSummary> skeletons,
                              database_.ListSkeletons());
    ToProto(skeletons, response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::GetSkeleton(grpc::ServerContext* context,
                                          const v1::GetSkeletonRequest* request,
                                          v1::SkeletonDetail* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const SkeletonMapView view,
                              ShowSkeleton(database_, request->skeleton_id(), answers_));
    ToProto(view, response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::MapSkeleton(grpc::ServerContext* context,
                                          const v1::MapSkeletonRequest* request,
                                          v1::SkeletonDetail* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::SlotOverrideChange change, FromProto(*request));
    MOTIONDB_ASSIGN_OR_RETURN(
        const SkeletonMapView view,
        catalog_.MapSkeleton(request->skeleton_id(), change, answers_, should_stop));
    ToProto(view, response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::GetClip(grpc::ServerContext* context,
                                      const v1::GetClipRequest* request, v1::Clip* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    // The record and skeleton only: the frames are not shown.
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipLayout layout,
                              database_.GetClipLayout(request->clip_id()));
    ToProto(layout, response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::DeleteClip(grpc::ServerContext* context,
                                         const v1::DeleteClipRequest* request,
                                         v1::DeleteClipResponse* /*response*/) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) {
    return catalog_.DeleteClip(request->clip_id(), should_stop);
  });
}

grpc::Status ClipServiceImpl::UpdateClip(grpc::ServerContext* context,
                                         const v1::UpdateClipRequest* request, v1::Clip* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const storage::ClipRecord updated,
        catalog_.UpdateClip(request->clip_id(), FromProto(*request), {}, should_stop));
    ToProto(updated, response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::ExportClip(grpc::ServerContext* context,
                                         const v1::ExportClipRequest* request,
                                         v1::ExportClipResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const ExportFormat format, ExportFormatFromProto(request->format()));
    MOTIONDB_ASSIGN_OR_RETURN(
        ExportedFile exported,
        server::ExportClip(database_, FromProto(request->clip()), format, answers_, should_stop));
    ToProto(std::move(exported), response);
    return absl::OkStatus();
  });
}

grpc::Status ClipServiceImpl::ExportClipStream(grpc::ServerContext* context,
                                               const v1::ExportClipRequest* request,
                                               grpc::ServerWriter<v1::ExportClipResponse>* writer) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const ExportFormat format, ExportFormatFromProto(request->format()));
    // Write blocks while the client's window is full, so a client that stops reading holds a
    // piece here, not the clip; it returns false once the call has ended.
    const auto send = [&](ExportedFile piece) -> absl::Status {
      v1::ExportClipResponse message;
      ToProto(std::move(piece), &message);
      if (!writer->Write(message)) return absl::CancelledError("the client stopped reading");
      return absl::OkStatus();
    };
    return StreamClipExport(database_, FromProto(request->clip()), format, answers_, send,
                            should_stop);
  });
}

}  // namespace motiondb::server
