// EditService's messages and the operators' types (server/edit/), both ways. Each request's
// parameters (without its output) are kept as proto3 JSON in EditOutput::parameters_json, for
// the provenance of a stored result; the results' BVH text is moved, as an export's is.
#ifndef MOTIONDB_SERVER_GRPC_EDIT_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_EDIT_CONVERSION_H_

#include <vector>

#include "absl/status/statusor.h"
#include "motiondb/v1/edit_service.pb.h"
#include "server/edit/blends.h"
#include "server/edit/curves.h"
#include "server/edit/pose_models.h"
#include "server/edit/reconstruct.h"
#include "server/edit/transitions.h"

namespace motiondb::server {

absl::StatusOr<ReconstructRequest> FromProto(const v1::ReconstructRequest& request);
absl::StatusOr<InterpolateRequest> FromProto(const v1::InterpolateRequest& request);
absl::StatusOr<BlendRequest> FromProto(const v1::BlendRequest& request);
absl::StatusOr<FillGapRequest> FromProto(const v1::FillGapRequest& request);
absl::StatusOr<ScaleRequest> FromProto(const v1::ScaleRequest& request);
// INVALID_ARGUMENT naming target unless exactly one of target and the axis is given.
absl::StatusOr<TranslateRequest> FromProto(const v1::TranslateRequest& request);
absl::StatusOr<SmoothRequest> FromProto(const v1::SmoothRequest& request);
absl::StatusOr<PoseModelRequest> FromProto(const v1::CreatePoseModelRequest& request);
absl::StatusOr<DetectRequest> FromProto(const v1::DetectPoseRequest& request);

void ToProto(EditResult&& result, v1::EditResult* out);
void ToProto(EditResult&& result, v1::EditResponse* response);
void ToProto(ReconstructOutcome&& outcome, v1::ReconstructResponse* response);
void ToProto(InterpolateOutcome&& outcome, v1::InterpolateResponse* response);
void ToProto(BlendOutcome&& outcome, v1::BlendResponse* response);
void ToProto(FillGapOutcome&& outcome, v1::FillGapResponse* response);
void ToProto(const StoredPoseModel& stored, v1::PoseModel* model);
void ToProto(const std::vector<StoredPoseModel>& models, v1::ListPoseModelsResponse* response);
// The log-likelihood as little-endian float32.
void ToProto(const DetectOutcome& outcome, v1::DetectPoseResponse* response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_EDIT_CONVERSION_H_
