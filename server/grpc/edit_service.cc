#include "server/grpc/edit_service.h"

#include <utility>

#include "server/edit/blends.h"
#include "server/edit/curves.h"
#include "server/edit/pose_models.h"
#include "server/edit/reconstruct.h"
#include "server/edit/transitions.h"
#include "server/grpc/edit_conversion.h"
#include "server/grpc/serve.h"
#include "util/status_macros.h"

namespace motiondb::server {

template <typename Request, typename Response, typename Operation>
grpc::Status EditServiceImpl::Operate(grpc::ServerContext* context, const Request& request,
                                      Response* response, const Operation& operation) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const auto converted, FromProto(request));
    MOTIONDB_ASSIGN_OR_RETURN(auto outcome, operation(context_, converted, should_stop));
    ToProto(std::move(outcome), response);
    return absl::OkStatus();
  });
}

grpc::Status EditServiceImpl::Reconstruct(grpc::ServerContext* context,
                                          const v1::ReconstructRequest* request,
                                          v1::ReconstructResponse* response) {
  return Operate(context, *request, response, server::Reconstruct);
}

grpc::Status EditServiceImpl::Interpolate(grpc::ServerContext* context,
                                          const v1::InterpolateRequest* request,
                                          v1::InterpolateResponse* response) {
  return Operate(context, *request, response, server::Interpolate);
}

grpc::Status EditServiceImpl::Blend(grpc::ServerContext* context, const v1::BlendRequest* request,
                                    v1::BlendResponse* response) {
  return Operate(context, *request, response, server::Blend);
}

grpc::Status EditServiceImpl::FillGap(grpc::ServerContext* context,
                                      const v1::FillGapRequest* request,
                                      v1::FillGapResponse* response) {
  return Operate(context, *request, response, server::FillGap);
}

grpc::Status EditServiceImpl::Scale(grpc::ServerContext* context, const v1::ScaleRequest* request,
                                    v1::EditResponse* response) {
  return Operate(context, *request, response, server::Scale);
}

grpc::Status EditServiceImpl::Translate(grpc::ServerContext* context,
                                        const v1::TranslateRequest* request,
                                        v1::EditResponse* response) {
  return Operate(context, *request, response, server::Translate);
}

grpc::Status EditServiceImpl::Smooth(grpc::ServerContext* context, const v1::SmoothRequest* request,
                                     v1::EditResponse* response) {
  return Operate(context, *request, response, server::Smooth);
}

grpc::Status EditServiceImpl::CreatePoseModel(grpc::ServerContext* context,
                                              const v1::CreatePoseModelRequest* request,
                                              v1::PoseModel* response) {
  return Operate(context, *request, response, server::CreatePoseModel);
}

grpc::Status EditServiceImpl::DetectPose(grpc::ServerContext* context,
                                         const v1::DetectPoseRequest* request,
                                         v1::DetectPoseResponse* response) {
  return Operate(context, *request, response, server::DetectPose);
}

grpc::Status EditServiceImpl::ListPoseModels(grpc::ServerContext* context,
                                             const v1::ListPoseModelsRequest* request,
                                             v1::ListPoseModelsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<StoredPoseModel> models,
                              server::ListPoseModels(context_, request->space()));
    ToProto(models, response);
    return absl::OkStatus();
  });
}

grpc::Status EditServiceImpl::DeletePoseModel(grpc::ServerContext* context,
                                              const v1::DeletePoseModelRequest* request,
                                              v1::DeletePoseModelResponse* /*response*/) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) {
    return server::DeletePoseModel(context_, request->name(), should_stop);
  });
}

}  // namespace motiondb::server
