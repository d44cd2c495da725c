#include "server/grpc/label_service.h"

#include "server/grpc/call_context.h"
#include "server/grpc/proto_conversion.h"
#include "server/grpc/status_conversion.h"
#include "server/label_catalog.h"

namespace motiondb::server {

grpc::Status LabelServiceImpl::AddLabels(grpc::ServerContext* context,
                                         const v1::AddLabelsRequest* request,
                                         v1::AddLabelsResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<storage::AddedLabels> added =
        server::AddLabels(database_, FromProto(*request), answers_, StopWhenCallEnds(context));
    if (!added.ok()) return ToGrpcStatus(ExplainStop(added.status(), context));
    for (const storage::LabelRecord& label : added->labels) ToProto(label, response->add_labels());
    for (const size_t item : added->skipped) response->add_skipped(static_cast<int32_t>(item));
    return grpc::Status::OK;
  });
}

grpc::Status LabelServiceImpl::ListLabels(grpc::ServerContext* context,
                                          const v1::ListLabelsRequest* request,
                                          v1::ListLabelsResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<storage::LabelFilter> filter = FromProto(*request);
    if (!filter.ok()) return ToGrpcStatus(filter.status());
    const absl::StatusOr<storage::LabelPage> page = server::ListLabels(
        database_, {request->page_size(), request->page_token()}, *filter, answers_);
    if (!page.ok()) return ToGrpcStatus(page.status());
    ToProto(*page, response);
    return grpc::Status::OK;
  });
}

grpc::Status LabelServiceImpl::DeleteLabels(grpc::ServerContext* context,
                                            const v1::DeleteLabelsRequest* request,
                                            v1::DeleteLabelsResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<LabelDeletion> deletion = FromProto(*request);
    if (!deletion.ok()) return ToGrpcStatus(deletion.status());
    const absl::StatusOr<int64_t> deleted =
        server::DeleteLabels(database_, *deletion, StopWhenCallEnds(context));
    if (!deleted.ok()) return ToGrpcStatus(ExplainStop(deleted.status(), context));
    response->set_deleted(*deleted);
    return grpc::Status::OK;
  });
}

grpc::Status LabelServiceImpl::FindLabels(grpc::ServerContext* context,
                                          const v1::FindLabelsRequest* request,
                                          v1::FindLabelsResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<storage::LabelPage> page = server::FindLabels(
        database_, {request->page_size(), request->page_token()}, FromProto(*request), answers_);
    if (!page.ok()) return ToGrpcStatus(page.status());
    ToProto(*page, response);
    return grpc::Status::OK;
  });
}

grpc::Status LabelServiceImpl::GetClipLabels(grpc::ServerContext* context,
                                             const v1::GetClipLabelsRequest* request,
                                             v1::GetClipLabelsResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<ClipTimeline> timeline = GetClipTimeline(
        database_, request->clip_id(), {request->page_size(), request->page_token()}, answers_);
    if (!timeline.ok()) return ToGrpcStatus(timeline.status());
    ToProto(*timeline, response);
    return grpc::Status::OK;
  });
}

}  // namespace motiondb::server
