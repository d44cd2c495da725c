#include "server/grpc/label_service.h"

#include "server/grpc/label_conversion.h"
#include "server/grpc/serve.h"
#include "server/label_catalog.h"
#include "util/status_macros.h"

namespace motiondb::server {

grpc::Status LabelServiceImpl::AddLabels(grpc::ServerContext* context,
                                         const v1::AddLabelsRequest* request,
                                         v1::AddLabelsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const storage::AddedLabels added,
        server::AddLabels(database_, FromProto(*request), answers_, should_stop));
    ToProto(added, response);
    return absl::OkStatus();
  });
}

grpc::Status LabelServiceImpl::ListLabels(grpc::ServerContext* context,
                                          const v1::ListLabelsRequest* request,
                                          v1::ListLabelsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::LabelFilter filter, FromProto(*request));
    MOTIONDB_ASSIGN_OR_RETURN(
        const storage::LabelPage page,
        server::ListLabels(database_, {request->page_size(), request->page_token()}, filter,
                           answers_));
    ToProto(page, response);
    return absl::OkStatus();
  });
}

grpc::Status LabelServiceImpl::DeleteLabels(grpc::ServerContext* context,
                                            const v1::DeleteLabelsRequest* request,
                                            v1::DeleteLabelsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const LabelDeletion deletion, FromProto(*request));
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t deleted,
                              server::DeleteLabels(database_, deletion, should_stop));
    ToProto(deleted, response);
    return absl::OkStatus();
  });
}

grpc::Status LabelServiceImpl::FindLabels(grpc::ServerContext* context,
                                          const v1::FindLabelsRequest* request,
                                          v1::FindLabelsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const storage::LabelPage page,
        server::FindLabels(database_, {request->page_size(), request->page_token()},
                           FromProto(*request), answers_));
    ToProto(page, response);
    return absl::OkStatus();
  });
}

grpc::Status LabelServiceImpl::GetClipLabels(grpc::ServerContext* context,
                                             const v1::GetClipLabelsRequest* request,
                                             v1::GetClipLabelsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const ClipTimeline timeline,
        GetClipTimeline(database_, request->clip_id(),
                        {request->page_size(), request->page_token()}, answers_));
    ToProto(timeline, response);
    return absl::OkStatus();
  });
}

}  // namespace motiondb::server
