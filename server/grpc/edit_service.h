// motiondb.v1.EditService: the Motion Curve operators on stored clips (issue 16), each a thin
// handler over server/edit/.
#ifndef MOTIONDB_SERVER_GRPC_EDIT_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_EDIT_SERVICE_H_

#include "motiondb/v1/edit_service.grpc.pb.h"
#include "server/edit/context.h"
#include "server/grpc/call_gate.h"

namespace motiondb::server {

class EditServiceImpl final : public v1::EditService::Service {
 public:
  EditServiceImpl(const EditContext& context, CallGate& gate) : context_(context), gate_(gate) {}

  grpc::Status Reconstruct(grpc::ServerContext* context, const v1::ReconstructRequest* request,
                           v1::ReconstructResponse* response) override;
  grpc::Status Interpolate(grpc::ServerContext* context, const v1::InterpolateRequest* request,
                           v1::InterpolateResponse* response) override;
  grpc::Status Blend(grpc::ServerContext* context, const v1::BlendRequest* request,
                     v1::BlendResponse* response) override;
  grpc::Status FillGap(grpc::ServerContext* context, const v1::FillGapRequest* request,
                       v1::FillGapResponse* response) override;
  grpc::Status Scale(grpc::ServerContext* context, const v1::ScaleRequest* request,
                     v1::EditResponse* response) override;
  grpc::Status Translate(grpc::ServerContext* context, const v1::TranslateRequest* request,
                         v1::EditResponse* response) override;
  grpc::Status Smooth(grpc::ServerContext* context, const v1::SmoothRequest* request,
                      v1::EditResponse* response) override;
  grpc::Status CreatePoseModel(grpc::ServerContext* context,
                               const v1::CreatePoseModelRequest* request,
                               v1::PoseModel* response) override;
  grpc::Status ListPoseModels(grpc::ServerContext* context,
                              const v1::ListPoseModelsRequest* request,
                              v1::ListPoseModelsResponse* response) override;
  grpc::Status DeletePoseModel(grpc::ServerContext* context,
                               const v1::DeletePoseModelRequest* request,
                               v1::DeletePoseModelResponse* response) override;
  grpc::Status DetectPose(grpc::ServerContext* context, const v1::DetectPoseRequest* request,
                          v1::DetectPoseResponse* response) override;

 private:
  // Converts `request`, runs `operation` on it and converts its outcome into `response`: every
  // operator's handler is this.
  template <typename Request, typename Response, typename Operation>
  grpc::Status Operate(grpc::ServerContext* context, const Request& request, Response* response,
                       const Operation& operation);

  EditContext context_;
  CallGate& gate_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_EDIT_SERVICE_H_
