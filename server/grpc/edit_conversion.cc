#include "server/grpc/edit_conversion.h"

#include <string>
#include <utility>

#include <google/protobuf/util/json_util.h>

#include "server/grpc/clip_conversion.h"
#include "server/grpc/internal/field_conversion.h"
#include "util/byte_coding.h"
#include "util/name_text.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

std::string JsonOf(const google::protobuf::Message& message) {
  std::string json;
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  if (!google::protobuf::util::MessageToJsonString(message, &json, options).ok()) return "{}";
  return json;
}

// The request as proto3 JSON without its `output`: what made a stored result.
template <typename Request>
std::string ParametersJson(const Request& request) {
  Request parameters = request;
  parameters.clear_output();
  return JsonOf(parameters);
}

// The parameters only for a result that is stored: a request's JSON is a copy of it (a blend's
// path of a million points takes seconds), made for nothing when the result is only answered.
template <typename Request>
EditOutput OutputOf(const Request& request) {
  const v1::EditOutput& output = request.output();
  return {output.store_name(),
          std::vector<std::string>(output.store_tags().begin(), output.store_tags().end()),
          output.store_name().empty() ? std::string() : ParametersJson(request)};
}

EditScope FromProto(const v1::EditScope& scope) {
  EditScope out;
  if (scope.has_gate()) {
    const v1::Gate& gate = scope.gate();
    out.gate = Gate{gate.start_s(), gate.end_s(), gate.lead_in_s(), gate.lead_out_s()};
  }
  out.dims.assign(scope.dims().begin(), scope.dims().end());
  return out;
}

JointConstraints FromProto(const v1::JointConstraints& constraints) {
  JointConstraints out;
  out.edit_weights.insert(constraints.edit_weights().begin(), constraints.edit_weights().end());
  out.max_angles.insert(constraints.max_angles().begin(), constraints.max_angles().end());
  out.source_margin = Optional(constraints.has_source_margin(), constraints.source_margin());
  return out;
}

template <typename Request>
CurveEdit CurveEditOf(const Request& request) {
  // Qualified: this namespace's own FromProto overloads would hide the public ones.
  return {request.space(), server::FromProto(request.clip()), FromProto(request.scope()),
          FromProto(request.constraints()), OutputOf(request)};
}

absl::StatusOr<CovarianceType> FromProto(v1::CovarianceType type) {
  switch (type) {
    case v1::COVARIANCE_TYPE_UNSPECIFIED:
    case v1::COVARIANCE_TYPE_FULL:
      return CovarianceType::kFull;
    case v1::COVARIANCE_TYPE_DIAGONAL:
      return CovarianceType::kDiagonal;
    case v1::COVARIANCE_TYPE_SPHERICAL:
      return CovarianceType::kSpherical;
    default:
      return UnknownValue("covariance", type);
  }
}

v1::CovarianceType ToProto(CovarianceType type) {
  switch (type) {
    case CovarianceType::kFull:
      return v1::COVARIANCE_TYPE_FULL;
    case CovarianceType::kDiagonal:
      return v1::COVARIANCE_TYPE_DIAGONAL;
    case CovarianceType::kSpherical:
      return v1::COVARIANCE_TYPE_SPHERICAL;
  }
  return v1::COVARIANCE_TYPE_UNSPECIFIED;
}

}  // namespace

absl::StatusOr<ReconstructRequest> FromProto(const v1::ReconstructRequest& request) {
  ReconstructRequest out{request.space(), FromProto(request.clip())};
  if (request.has_dims()) out.options.dims = request.dims();
  out.options.error_curve = request.error_curve();
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<InterpolateRequest> FromProto(const v1::InterpolateRequest& request) {
  InterpolateRequest out{request.space(), FromProto(request.from()), FromProto(request.to())};
  out.options.t.assign(request.t().begin(), request.t().end());
  if (request.has_steps()) out.options.steps = request.steps();
  if (request.has_dims()) out.options.dims = request.dims();
  switch (request.method()) {
    case v1::INTERPOLATION_METHOD_UNSPECIFIED:
    case v1::INTERPOLATION_METHOD_MC_LERP:
      out.method = InterpolationMethod::kMcLerp;
      break;
    case v1::INTERPOLATION_METHOD_SLERP:
      out.method = InterpolationMethod::kSlerp;
      break;
    default:
      return UnknownValue("method", request.method());
  }
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<BlendRequest> FromProto(const v1::BlendRequest& request) {
  BlendRequest out{request.space()};
  for (const v1::PlanarPose& pose : request.poses()) {
    out.poses.push_back({FromProto(pose.pose()), pose.x(), pose.y()});
  }
  for (const v1::PlanePoint& point : request.path()) out.path.emplace_back(point.x(), point.y());
  if (request.has_frames_per_segment()) out.frames_per_segment = request.frames_per_segment();
  if (request.has_epsilon()) out.options.epsilon = request.epsilon();
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<FillGapRequest> FromProto(const v1::FillGapRequest& request) {
  FillGapRequest out{request.space(), FromProto(request.first()), FromProto(request.second())};
  if (request.has_gap_s()) out.gap_s = request.gap_s();
  switch (request.method()) {
    case v1::GAP_METHOD_UNSPECIFIED:
    case v1::GAP_METHOD_HERMITE:
      out.gap.method = GapMethod::kHermite;
      break;
    case v1::GAP_METHOD_LINEAR:
      out.gap.method = GapMethod::kLinear;
      break;
    default:
      return UnknownValue("method", request.method());
  }
  if (request.has_damping()) out.gap.damping = request.damping();
  out.gap.derivative_smoothing = request.derivative_smoothing();
  out.overlap_s = request.overlap_s();
  out.blend.align = !request.no_align();
  if (request.has_slope_limit()) out.blend.warp.slope_limit = request.slope_limit();
  if (request.has_warp_dims()) out.blend.warp.dims = request.warp_dims();
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<ScaleRequest> FromProto(const v1::ScaleRequest& request) {
  ScaleRequest out{CurveEditOf(request)};
  if (request.has_factor()) out.options.factor = request.factor();
  switch (request.centre()) {
    case v1::SCALE_CENTRE_UNSPECIFIED:
    case v1::SCALE_CENTRE_ORIGIN:
      out.options.centre = ScaleCentre::kOrigin;
      break;
    case v1::SCALE_CENTRE_SELECTION_MEAN:
      out.options.centre = ScaleCentre::kSelectionMean;
      break;
    default:
      return UnknownValue("centre", request.centre());
  }
  if (request.has_sigmoid()) {
    out.options.sigmoid = Sigmoid{request.sigmoid().threshold(), request.sigmoid().width()};
  }
  return out;
}

absl::StatusOr<TranslateRequest> FromProto(const v1::TranslateRequest& request) {
  TranslateRequest out{CurveEditOf(request)};
  const bool axis = request.has_axis_from() || request.has_axis_to();
  if (request.has_target() == axis ||
      (axis && !(request.has_axis_from() && request.has_axis_to()))) {
    return absl::InvalidArgumentError(
        "target: give a target pose, or axis_from and axis_to, not both");
  }
  if (request.has_target()) {
    out.options.mode = TranslateMode::kTowardPose;
    out.poses = {FromProto(request.target())};
  } else {
    out.options.mode = TranslateMode::kAlongAxis;
    out.poses = {FromProto(request.axis_from()), FromProto(request.axis_to())};
  }
  if (request.has_amount()) out.options.amount = request.amount();
  return out;
}

absl::StatusOr<SmoothRequest> FromProto(const v1::SmoothRequest& request) {
  SmoothRequest out{CurveEditOf(request)};
  if (request.has_level()) out.options.level = request.level();
  return out;
}

absl::StatusOr<PoseModelRequest> FromProto(const v1::CreatePoseModelRequest& request) {
  PoseModelRequest out{request.name(), request.space()};
  for (const v1::ClipRange& range : request.examples()) out.examples.push_back(FromProto(range));
  PoseModelOptions& options = out.options;
  if (request.has_components()) options.components = request.components();
  MOTIONDB_ASSIGN_OR_RETURN(options.covariance, FromProto(request.covariance()));
  if (request.has_dims()) options.dims = request.dims();
  if (request.has_seed()) options.seed = request.seed();
  if (request.has_threshold_quantile()) options.threshold_quantile = request.threshold_quantile();
  if (request.has_max_iterations()) options.max_iterations = request.max_iterations();
  out.parameters_json = JsonOf(request);
  return out;
}

absl::StatusOr<DetectRequest> FromProto(const v1::DetectPoseRequest& request) {
  return DetectRequest{request.model(), FromProto(request.clip()),
                       Optional(request.has_threshold(), request.threshold()),
                       request.min_duration_s()};
}

void ToProto(EditResult&& result, v1::EditResult* out) {
  out->set_bvh(std::move(result.bvh));
  out->set_file_name(result.file_name);
  out->set_frames(result.frames);
  out->set_fps(result.fps);
  if (result.stored) ToProto(*result.stored, out->mutable_stored());
}

void ToProto(EditResult&& result, v1::EditResponse* response) {
  ToProto(std::move(result), response->mutable_result());
}

void ToProto(ReconstructOutcome&& outcome, v1::ReconstructResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  response->set_dims(outcome.dims);
  for (const JointReconstructionError& joint : outcome.joints) {
    v1::JointError* out = response->add_joints();
    out->set_joint(ValidUtf8(joint.joint));
    out->set_mean_rad(joint.error.mean_rad);
    out->set_max_rad(joint.error.max_rad);
  }
  response->set_mean_rad(outcome.overall.mean_rad);
  response->set_max_rad(outcome.overall.max_rad);
  for (const ReconstructionError& level : outcome.curve) {
    v1::ReconstructionError* out = response->add_curve();
    out->set_dims(level.dims);
    out->set_mean_rad(level.mean_rad);
    out->set_max_rad(level.max_rad);
  }
}

void ToProto(InterpolateOutcome&& outcome, v1::InterpolateResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  response->set_other_bvh(std::move(outcome.other_bvh));
  const Interpolation& comparison = outcome.comparison;
  for (size_t i = 0; i < comparison.t.size(); ++i) {
    v1::InterpolationStep* step = response->add_steps();
    step->set_t(comparison.t[i]);
    step->set_mean_rad(comparison.difference[i].mean_rad);
    step->set_max_rad(comparison.difference[i].max_rad);
    step->set_curve_distance(comparison.curve_distance[i]);
  }
  response->set_mean_rad(comparison.overall.mean_rad);
  response->set_max_rad(comparison.overall.max_rad);
}

void ToProto(BlendOutcome&& outcome, v1::BlendResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  for (Eigen::Index k = 0; k < outcome.weights.rows(); ++k) {
    v1::BlendWeights* frame = response->add_frames();
    for (Eigen::Index i = 0; i < outcome.weights.cols(); ++i) {
      frame->add_weights(outcome.weights(k, i));
    }
  }
}

void ToProto(FillGapOutcome&& outcome, v1::FillGapResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  response->set_transition_frames(outcome.transition_frames);
  for (const SeamJump& seam : outcome.seams) {
    v1::SeamJump* out = response->add_seams();
    out->set_mean_rad_s(seam.chosen.mean_rad);
    out->set_max_rad_s(seam.chosen.max_rad);
    out->set_linear_mean_rad_s(seam.linear.mean_rad);
    out->set_linear_max_rad_s(seam.linear.max_rad);
  }
  response->set_warp_score(outcome.warp_score);
}

void ToProto(const StoredPoseModel& stored, v1::PoseModel* model) {
  model->set_name(stored.record.name);
  model->set_space(stored.record.space_name);
  model->set_dims(stored.model.dims);
  model->set_components(static_cast<int32_t>(stored.model.weights.size()));
  model->set_covariance(ToProto(stored.model.covariance));
  model->set_threshold(stored.model.threshold);
  model->set_log_likelihood(stored.model.log_likelihood);
  model->set_iterations(stored.model.iterations);
  for (const double weight : stored.model.weights) model->add_weights(weight);
  model->set_created_unix_ms(stored.record.created_unix_ms);
  model->set_parameters_json(stored.record.parameters_json);
}

void ToProto(const DetectOutcome& outcome, v1::DetectPoseResponse* response) {
  response->set_space(outcome.space);
  response->set_first_frame(outcome.frames.first);
  response->set_last_frame(outcome.frames.last);
  response->set_sample_rate(outcome.sample_rate);
  const Eigen::VectorXf values = outcome.log_likelihood.cast<float>();
  AppendFloat32s(values.data(), values.size(), response->mutable_log_likelihood());
  response->set_threshold(outcome.threshold);
  for (const DetectedRange& range : outcome.intervals) {
    v1::DetectedInterval* out = response->add_intervals();
    out->set_first_frame(range.first_frame);
    out->set_last_frame(range.last_frame);
    out->set_start_s(range.start_s);
    out->set_end_s(range.end_s);
    out->set_peak_frame(range.peak_frame);
    out->set_peak(range.peak);
  }
}

void ToProto(const std::vector<StoredPoseModel>& models, v1::ListPoseModelsResponse* response) {
  for (const StoredPoseModel& model : models) ToProto(model, response->add_models());
}

}  // namespace motiondb::server
