#include "server/grpc/space_service.h"

#include <memory>

#include "server/grpc/serve.h"
#include "server/grpc/space_conversion.h"
#include "server/listing.h"
#include "server/space_curve.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"

namespace motiondb::server {

grpc::Status SpaceServiceImpl::CreateSpace(grpc::ServerContext* context,
                                           const v1::CreateSpaceRequest* request,
                                           v1::Space* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const SpaceRequest space, FromProto(*request));
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> created,
                              catalog_.CreateSpace(space, should_stop));
    ToProto(*created, response);
    return absl::OkStatus();
  });
}

grpc::Status SpaceServiceImpl::ListSpaces(grpc::ServerContext* context,
                                          const v1::ListSpacesRequest* request,
                                          v1::ListSpacesResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const SpacePage page,
        server::ListSpaces(registry_, {request->page_size(), request->page_token()}));
    ToProto(page, response);
    return absl::OkStatus();
  });
}

grpc::Status SpaceServiceImpl::GetSpace(grpc::ServerContext* context,
                                        const v1::GetSpaceRequest* request, v1::Space* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                              FindSpace(registry_, request->name()));
    ToProto(*snapshot, response);
    return absl::OkStatus();
  });
}

grpc::Status SpaceServiceImpl::DeleteSpace(grpc::ServerContext* context,
                                           const v1::DeleteSpaceRequest* request,
                                           v1::DeleteSpaceResponse* /*response*/) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) {
    return catalog_.DeleteSpace(request->name(), should_stop);
  });
}

grpc::Status SpaceServiceImpl::GetCurve(grpc::ServerContext* context,
                                        const v1::GetCurveRequest* request,
                                        v1::GetCurveResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const Curve curve,
        ReadCurve(registry_, database_, FromProto(*request), answers_, should_stop));
    ToProto(curve, response);
    return absl::OkStatus();
  });
}

}  // namespace motiondb::server
