#include "server/grpc/space_service.h"

#include "server/grpc/call_context.h"
#include "server/grpc/proto_conversion.h"
#include "server/grpc/status_conversion.h"
#include "server/listing.h"
#include "server/space_curve.h"
#include "server/space_lookup.h"

namespace motiondb::server {

grpc::Status SpaceServiceImpl::CreateSpace(grpc::ServerContext* context,
                                           const v1::CreateSpaceRequest* request,
                                           v1::Space* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<SpaceRequest> space_request = FromProto(*request);
    if (!space_request.ok()) return ToGrpcStatus(space_request.status());
    const absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> snapshot =
        catalog_.CreateSpace(*space_request, StopWhenCallEnds(context));
    if (!snapshot.ok()) return ToGrpcStatus(ExplainStop(snapshot.status(), context));
    ToProto(**snapshot, response);
    return grpc::Status::OK;
  });
}

grpc::Status SpaceServiceImpl::ListSpaces(grpc::ServerContext* context,
                                          const v1::ListSpacesRequest* request,
                                          v1::ListSpacesResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<SpacePage> page =
        server::ListSpaces(registry_, {request->page_size(), request->page_token()});
    if (!page.ok()) return ToGrpcStatus(page.status());
    for (const auto& snapshot : page->spaces) ToProto(*snapshot, response->add_spaces());
    response->set_next_page_token(page->next_page_token);
    return grpc::Status::OK;
  });
}

grpc::Status SpaceServiceImpl::GetSpace(grpc::ServerContext* context,
                                        const v1::GetSpaceRequest* request, v1::Space* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> snapshot =
        FindSpace(registry_, request->name());
    if (!snapshot.ok()) return ToGrpcStatus(snapshot.status());
    ToProto(**snapshot, response);
    return grpc::Status::OK;
  });
}

grpc::Status SpaceServiceImpl::DeleteSpace(grpc::ServerContext* context,
                                           const v1::DeleteSpaceRequest* request,
                                           v1::DeleteSpaceResponse* /*response*/) {
  return gate_.Run(context, [&]() -> grpc::Status {
    return ToGrpcStatus(
        ExplainStop(catalog_.DeleteSpace(request->name(), StopWhenCallEnds(context)), context));
  });
}

grpc::Status SpaceServiceImpl::GetCurve(grpc::ServerContext* context,
                                        const v1::GetCurveRequest* request,
                                        v1::GetCurveResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<Curve> curve =
        ReadCurve(registry_, database_, FromProto(*request), answers_, StopWhenCallEnds(context));
    if (!curve.ok()) return ToGrpcStatus(ExplainStop(curve.status(), context));
    ToProto(*curve, response);
    return grpc::Status::OK;
  });
}

}  // namespace motiondb::server
