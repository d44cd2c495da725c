#include "server/grpc/shard_service.h"

#include "absl/strings/str_cat.h"
#include "server/grpc/call_context.h"
#include "server/grpc/clip_conversion.h"
#include "server/grpc/internal/upload_ingest.h"
#include "server/grpc/serve.h"
#include "util/status_macros.h"

namespace motiondb::server {

grpc::Status ShardServiceImpl::StoreTake(grpc::ServerContext* context,
                                         const shard::v1::StoreTakeRequest* request,
                                         v1::IngestClipResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(IngestRequest ingest, FromProto(request->ingest()));
    if (request->clip_id() < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("clip_id: ", request->clip_id(), "; a routed take needs a positive id"));
    }
    ingest.routed = IngestRequest::Routed{.take = request->take(), .clip_id = request->clip_id()};
    MOTIONDB_RETURN_IF_ERROR(check_owner_(request->clip_id(), WaitDeadlineOf(*context)));
    return IngestUploadedFile({catalog_, limits_, budget_, metrics_}, ingest,
                              request->ingest().bvh(), should_stop, response);
  });
}

grpc::Status ShardServiceImpl::UpdateClip(grpc::ServerContext* context,
                                          const v1::UpdateClipRequest* request,
                                          v1::Clip* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_RETURN_IF_ERROR(check_owner_(request->clip_id(), WaitDeadlineOf(*context)));
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord updated,
                              catalog_.UpdateClip(request->clip_id(), FromProto(*request),
                                                  {.name_reserved = true}, should_stop));
    ToProto(updated, response);
    return absl::OkStatus();
  });
}

}  // namespace motiondb::server
