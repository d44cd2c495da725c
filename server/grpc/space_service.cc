#include "server/grpc/space_service.h"

#include <algorithm>
#include <cstring>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "core/space/joint_weights.h"
#include "server/frame_conversion.h"
#include "server/grpc/call_context.h"
#include "server/grpc/status_conversion.h"
#include "server/paging.h"
#include "server/space_lookup.h"
#include "server/space_report.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

constexpr int kDefaultCurveDims = 3;

absl::StatusOr<WeightPreset> ToWeightPreset(v1::WeightPreset preset) {
  switch (preset) {
    case v1::WEIGHT_PRESET_UNSPECIFIED:
    case v1::WEIGHT_PRESET_MASS:
      return WeightPreset::kMass;
    case v1::WEIGHT_PRESET_UNIFORM:
      return WeightPreset::kUniform;
    default:
      return absl::InvalidArgumentError(absl::StrCat("weight_preset: unknown value ", preset));
  }
}

absl::StatusOr<SpaceMetric> ToSpaceMetric(v1::SpaceMetric metric) {
  switch (metric) {
    case v1::SPACE_METRIC_UNSPECIFIED:
    case v1::SPACE_METRIC_UNIT:
      return SpaceMetric::kUnit;
    case v1::SPACE_METRIC_EIGENVALUE_SCALED:
      return SpaceMetric::kEigenvalueScaled;
    default:
      return absl::InvalidArgumentError(absl::StrCat("metric: unknown value ", metric));
  }
}

// Little-endian float32, as the API promises, whatever the host's byte order.
void AppendFloatLe(float value, std::string* out) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((bits >> (8 * i)) & 0xff));
}

}  // namespace

absl::StatusOr<SpaceRequest> ToSpaceRequest(const v1::CreateSpaceRequest& request) {
  SpaceRequest out;
  out.name = request.name();
  if (request.has_skeleton_id()) out.skeleton_id = request.skeleton_id();
  for (const v1::ClipRange& range : request.training()) {
    TrainingRange& training = out.training.emplace_back();
    training.clip_id = range.clip_id();
    if (range.has_first_frame()) training.first_frame = range.first_frame();
    if (range.has_last_frame()) training.last_frame = range.last_frame();
  }
  SpaceOptions& options = out.options;
  if (request.has_sample_rate()) options.sample_rate = request.sample_rate();
  MOTIONDB_ASSIGN_OR_RETURN(options.weights.preset, ToWeightPreset(request.weight_preset()));
  if (!request.weight_overrides().empty() && !request.weights_json().empty()) {
    return absl::InvalidArgumentError("give weight_overrides or weights_json, not both");
  }
  for (const auto& [joint, weight] : request.weight_overrides()) {
    options.weights.overrides[joint] = weight;
  }
  if (!request.weights_json().empty()) {
    absl::StatusOr<std::map<std::string, double>> overrides =
        ParseWeightOverrides(request.weights_json());
    if (!overrides.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("weights_json: ", overrides.status().message()));
    }
    options.weights.overrides = *std::move(overrides);
  }
  options.pose.remove_heading = !request.keep_heading();
  if (request.has_yaw_rate_weight()) options.yaw_rate_weight = request.yaw_rate_weight();
  MOTIONDB_ASSIGN_OR_RETURN(options.metric, ToSpaceMetric(request.metric()));
  return out;
}

absl::Status SpaceServiceImpl::Create(const v1::CreateSpaceRequest& request,
                                      grpc::ServerContext* context, v1::Space* response) {
  MOTIONDB_ASSIGN_OR_RETURN(const SpaceRequest space_request, ToSpaceRequest(request));
  absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> snapshot =
      library_.CreateSpace(space_request, StopWhenCallEnds(context));
  if (!snapshot.ok()) return ExplainStop(snapshot.status(), context);
  FillSpace(**snapshot, response);
  return absl::OkStatus();
}

grpc::Status SpaceServiceImpl::CreateSpace(grpc::ServerContext* context,
                                           const v1::CreateSpaceRequest* request,
                                           v1::Space* response) {
  return ToGrpcStatus(Create(*request, context, response));
}

absl::Status SpaceServiceImpl::List(const v1::ListSpacesRequest& request,
                                    v1::ListSpacesResponse* response) {
  MOTIONDB_ASSIGN_OR_RETURN(const int page_size, ResolvePageSize(request.page_size()));
  // The token is the last space id of the previous page: stable while spaces come and go.
  int64_t after = 0;
  if (!request.page_token().empty() && !absl::SimpleAtoi(request.page_token(), &after)) {
    return absl::InvalidArgumentError(
        absl::StrCat("page_token: '", request.page_token(), "' is not a token this server gave"));
  }
  const std::vector<std::shared_ptr<const SpaceSnapshot>> spaces = registry_.All();
  int listed = 0;
  for (const auto& snapshot : spaces) {
    if (snapshot->record.space_id <= after) continue;
    if (listed == page_size) {
      response->set_next_page_token(absl::StrCat(after));
      break;
    }
    FillSpace(*snapshot, response->add_spaces());
    after = snapshot->record.space_id;
    ++listed;
  }
  return absl::OkStatus();
}

grpc::Status SpaceServiceImpl::ListSpaces(grpc::ServerContext* /*context*/,
                                          const v1::ListSpacesRequest* request,
                                          v1::ListSpacesResponse* response) {
  return ToGrpcStatus(List(*request, response));
}

grpc::Status SpaceServiceImpl::GetSpace(grpc::ServerContext* /*context*/,
                                        const v1::GetSpaceRequest* request, v1::Space* response) {
  const absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> snapshot =
      FindSpace(registry_, request->name());
  if (!snapshot.ok()) return ToGrpcStatus(snapshot.status());
  FillSpace(**snapshot, response);
  return grpc::Status::OK;
}

grpc::Status SpaceServiceImpl::DeleteSpace(grpc::ServerContext* /*context*/,
                                           const v1::DeleteSpaceRequest* request,
                                           v1::DeleteSpaceResponse* /*response*/) {
  return ToGrpcStatus(library_.DeleteSpace(request->name()));
}

absl::Status SpaceServiceImpl::Curve(const v1::GetCurveRequest& request,
                                     v1::GetCurveResponse* response) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(registry_, request.space()));
  const int64_t clip_id = request.clip().clip_id();
  MOTIONDB_RETURN_IF_ERROR(CheckClipInSpace(database_, *snapshot, clip_id));
  const int space_dims = snapshot->space->dims();
  const int dims = request.has_dims() ? request.dims() : std::min(kDefaultCurveDims, space_dims);
  if (dims < 1 || dims > space_dims) {
    return absl::InvalidArgumentError(
        absl::StrCat("dims: ", dims, " is outside 1..", space_dims, " (the space's dimensions)"));
  }
  const IndexedClipInfo& info = snapshot->clips.at(clip_id);
  MOTIONDB_ASSIGN_OR_RETURN(const FrameRange frames,
                            ResolveFrameRange(request.clip(), info.frame_count, "clip"));
  const auto [first, last] = snapshot->Conversion(clip_id).ToSpace(frames);
  const CoordinateView rows = snapshot->index->clip_coordinates(snapshot->index->FindClip(clip_id))
                                  .middle_rows(first, last - first + 1);
  // The index holds coordinates multiplied by the metric's scales; a plot wants the projection.
  MOTIONDB_ASSIGN_OR_RETURN(const Eigen::VectorXd scales, snapshot->space->MetricScales(dims));
  std::string* bytes = response->mutable_coordinates();
  bytes->reserve(static_cast<size_t>(rows.rows) * dims * 4);
  for (int64_t r = 0; r < rows.rows; ++r) {
    for (int d = 0; d < dims; ++d) {
      AppendFloatLe(scales[d] > 0 ? static_cast<float>(rows.row(r)[d] / scales[d]) : 0.0f, bytes);
    }
  }
  response->set_dims(dims);
  response->set_frames(static_cast<int32_t>(rows.rows));
  response->set_sample_rate(snapshot->space->sample_rate());
  response->set_first_frame(frames.first);
  response->set_last_frame(frames.last);
  return absl::OkStatus();
}

grpc::Status SpaceServiceImpl::GetCurve(grpc::ServerContext* /*context*/,
                                        const v1::GetCurveRequest* request,
                                        v1::GetCurveResponse* response) {
  return ToGrpcStatus(Curve(*request, response));
}

}  // namespace motiondb::server
