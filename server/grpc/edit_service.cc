#include "server/grpc/edit_service.h"

#include <utility>

#include "server/edit_blends.h"
#include "server/edit_curves.h"
#include "server/edit_reconstruct.h"
#include "server/edit_transitions.h"
#include "server/grpc/call_context.h"
#include "server/grpc/proto_conversion.h"
#include "server/grpc/status_conversion.h"
#include "server/pose_models.h"

namespace motiondb::server {

template <typename Request, typename Response, typename Operation>
grpc::Status EditServiceImpl::Serve(grpc::ServerContext* context, const Request& request,
                                    Response* response, const Operation& operation) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const auto converted = FromProto(request);
    if (!converted.ok()) return ToGrpcStatus(converted.status());
    auto outcome = operation(context_, *converted, StopWhenCallEnds(context));
    if (!outcome.ok()) return ToGrpcStatus(ExplainStop(outcome.status(), context));
    ToProto(*std::move(outcome), response);
    return grpc::Status::OK;
  });
}

grpc::Status EditServiceImpl::Reconstruct(grpc::ServerContext* context,
                                          const v1::ReconstructRequest* request,
                                          v1::ReconstructResponse* response) {
  return Serve(context, *request, response, server::Reconstruct);
}

grpc::Status EditServiceImpl::Interpolate(grpc::ServerContext* context,
                                          const v1::InterpolateRequest* request,
                                          v1::InterpolateResponse* response) {
  return Serve(context, *request, response, server::Interpolate);
}

grpc::Status EditServiceImpl::Blend(grpc::ServerContext* context, const v1::BlendRequest* request,
                                    v1::BlendResponse* response) {
  return Serve(context, *request, response, server::Blend);
}

grpc::Status EditServiceImpl::FillGap(grpc::ServerContext* context,
                                      const v1::FillGapRequest* request,
                                      v1::FillGapResponse* response) {
  return Serve(context, *request, response, server::FillGap);
}

grpc::Status EditServiceImpl::Scale(grpc::ServerContext* context, const v1::ScaleRequest* request,
                                    v1::EditResponse* response) {
  return Serve(context, *request, response, server::Scale);
}

grpc::Status EditServiceImpl::Translate(grpc::ServerContext* context,
                                        const v1::TranslateRequest* request,
                                        v1::EditResponse* response) {
  return Serve(context, *request, response, server::Translate);
}

grpc::Status EditServiceImpl::Smooth(grpc::ServerContext* context, const v1::SmoothRequest* request,
                                     v1::EditResponse* response) {
  return Serve(context, *request, response, server::Smooth);
}

grpc::Status EditServiceImpl::CreatePoseModel(grpc::ServerContext* context,
                                              const v1::CreatePoseModelRequest* request,
                                              v1::PoseModel* response) {
  return Serve(context, *request, response, server::CreatePoseModel);
}

grpc::Status EditServiceImpl::DetectPose(grpc::ServerContext* context,
                                         const v1::DetectPoseRequest* request,
                                         v1::DetectPoseResponse* response) {
  return Serve(context, *request, response, server::DetectPose);
}

grpc::Status EditServiceImpl::ListPoseModels(grpc::ServerContext* context,
                                             const v1::ListPoseModelsRequest* request,
                                             v1::ListPoseModelsResponse* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<std::vector<StoredPoseModel>> models =
        server::ListPoseModels(context_, request->space());
    if (!models.ok()) return ToGrpcStatus(models.status());
    for (const StoredPoseModel& model : *models) ToProto(model, response->add_models());
    return grpc::Status::OK;
  });
}

grpc::Status EditServiceImpl::DeletePoseModel(grpc::ServerContext* context,
                                              const v1::DeletePoseModelRequest* request,
                                              v1::DeletePoseModelResponse* /*response*/) {
  return gate_.Run(context, [&]() -> grpc::Status {
    return ToGrpcStatus(ExplainStop(
        server::DeletePoseModel(context_, request->name(), StopWhenCallEnds(context)), context));
  });
}

}  // namespace motiondb::server
