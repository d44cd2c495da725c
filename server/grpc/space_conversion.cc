#include "server/grpc/space_conversion.h"

#include <map>
#include <string>
#include <utility>

#include "core/space/joint_weights.h"
#include "server/grpc/clip_conversion.h"
#include "server/grpc/internal/field_conversion.h"
#include "util/byte_coding.h"
#include "util/name_text.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {
namespace {

absl::StatusOr<WeightPreset> FromProto(v1::WeightPreset preset) {
  switch (preset) {
    case v1::WEIGHT_PRESET_UNSPECIFIED:
    case v1::WEIGHT_PRESET_MASS:
      return WeightPreset::kMass;
    case v1::WEIGHT_PRESET_UNIFORM:
      return WeightPreset::kUniform;
    default:
      return UnknownValue("weight_preset", preset);
  }
}

absl::StatusOr<SpaceMetric> FromProto(v1::SpaceMetric metric) {
  switch (metric) {
    case v1::SPACE_METRIC_UNSPECIFIED:
    case v1::SPACE_METRIC_UNIT:
      return SpaceMetric::kUnit;
    case v1::SPACE_METRIC_EIGENVALUE_SCALED:
      return SpaceMetric::kEigenvalueScaled;
    default:
      return UnknownValue("metric", metric);
  }
}

v1::SpaceMetric ToProto(SpaceMetric metric) {
  return metric == SpaceMetric::kUnit ? v1::SPACE_METRIC_UNIT : v1::SPACE_METRIC_EIGENVALUE_SCALED;
}

v1::WeightPreset ToProto(WeightPreset preset) {
  return preset == WeightPreset::kMass ? v1::WEIGHT_PRESET_MASS : v1::WEIGHT_PRESET_UNIFORM;
}

}  // namespace

absl::StatusOr<SpaceRequest> FromProto(const v1::CreateSpaceRequest& request) {
  SpaceRequest out;
  out.name = request.name();
  if (request.has_skeleton_id()) out.skeleton_id = request.skeleton_id();
  out.skeleton_ids.assign(request.skeleton_ids().begin(), request.skeleton_ids().end());
  for (const v1::ClipRange& range : request.training()) out.training.push_back(FromProto(range));
  SpaceOptions& options = out.options;
  if (request.has_sample_rate()) options.sample_rate = request.sample_rate();
  MOTIONDB_ASSIGN_OR_RETURN(options.weights.preset, FromProto(request.weight_preset()));
  if (!request.weight_overrides().empty() && !request.weights_json().empty()) {
    return absl::InvalidArgumentError("give weight_overrides or weights_json, not both");
  }
  for (const auto& [joint, weight] : request.weight_overrides()) {
    options.weights.overrides[joint] = weight;
  }
  if (!request.weights_json().empty()) {
    absl::StatusOr<std::map<std::string, double>> overrides =
        Prefixed("weights_json", ParseWeightOverrides(request.weights_json()));
    if (!overrides.ok()) return absl::InvalidArgumentError(overrides.status().message());
    options.weights.overrides = *std::move(overrides);
  }
  options.pose.remove_heading = !request.keep_heading();
  if (request.has_yaw_rate_weight()) options.yaw_rate_weight = request.yaw_rate_weight();
  if (request.has_root_velocity_weight()) {
    options.pose.root_velocity = request.root_velocity_weight() != 0;
    if (options.pose.root_velocity) options.root_velocity_weight = request.root_velocity_weight();
  }
  MOTIONDB_ASSIGN_OR_RETURN(options.metric, FromProto(request.metric()));
  if (request.has_learned_metric()) {
    LearnedMetricOptions& learned = out.learned_metric.emplace();
    if (request.learned_metric().has_shrink()) learned.shrink = request.learned_metric().shrink();
    // "learned_metric.shrink: ...", the field's path, as the CLI names its flag by it.
    if (const absl::Status valid = ValidateLearnedMetricOptions(learned); !valid.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("learned_metric.", valid.message()));
    }
  }
  return out;
}

CurveRequest FromProto(const v1::GetCurveRequest& request) {
  return {request.space(), FromProto(request.clip()), Optional(request.has_dims(), request.dims())};
}

void ToProto(const SpaceReport& report, v1::SpaceBuildReport* out) {
  out->set_dims(report.dims);
  out->set_joint_count(report.joint_count);
  out->set_pelvis(report.pelvis);
  out->set_sample_rate(report.sample_rate);
  out->set_heading_removed(report.heading_removed);
  out->set_yaw_rate_weight(report.yaw_rate_weight);
  out->set_root_velocity_weight(report.root_velocity_weight);
  out->set_metric(ToProto(report.metric));
  out->set_weight_preset(ToProto(report.weight_preset));
  for (const JointWeightReport& weight : report.joint_weights) {
    v1::JointWeight* joint = out->add_joint_weights();
    joint->set_joint(ValidUtf8(weight.joint));
    joint->set_weight(weight.weight);
  }
  for (const TrainingReport& range : report.training) {
    v1::ClipRange* used = out->add_training();
    used->set_clip_id(range.clip_id);
    used->set_first_frame(range.frames.first);
    used->set_last_frame(range.frames.last);
  }
  out->set_training_frames(report.training_frames);
  for (const double value : report.explained_variance) out->add_explained_variance(value);
  for (const ReconstructionError& error : report.reconstruction_error) {
    v1::ReconstructionError* measured = out->add_reconstruction_error();
    measured->set_dims(error.dims);
    measured->set_mean_rad(error.mean_rad);
    measured->set_max_rad(error.max_rad);
  }
  out->set_projected_clips(report.projected_clips);
  if (report.learned_metric_examples > 0) {
    v1::LearnedMetricReport* learned = out->mutable_learned_metric();
    learned->set_shrink(report.learned_metric_shrink);
    learned->set_examples(report.learned_metric_examples);
    learned->set_descriptors(report.learned_metric_descriptors);
  }
  out->set_build_ms(report.build_ms);
}

void ToProto(const SpaceSnapshot& snapshot, v1::SpaceIndex* index) {
  index->set_dims(snapshot.space->dims());
  if (!snapshot.index) return;
  index->set_clips(snapshot.index->clip_count());
  index->set_frames(snapshot.index->total_frames());
  index->set_ann_dims(snapshot.index->ann_dims());
  index->set_coordinate_bytes(snapshot.coordinate_bytes());
  index->set_tree_bytes(snapshot.tree_bytes());
}

void ToProto(const SpaceSnapshot& snapshot, v1::Space* space) {
  const storage::SpaceRecord& record = snapshot.record;
  space->set_space_id(record.space_id);
  space->set_name(record.name);
  space->set_skeleton_id(record.skeleton_id);
  for (const int64_t id : record.skeleton_ids) space->add_skeleton_ids(id);
  space->set_representation(std::string(SpaceRepresentationName(snapshot.space->representation())));
  space->set_version(record.version);
  space->set_created_unix_ms(record.created_unix_ms);
  ToProto(ReportFromJson(record.build_report_json, *snapshot.space), space->mutable_report());
  ToProto(snapshot, space->mutable_index());
}

void ToProto(const Curve& curve, v1::GetCurveResponse* response) {
  response->set_dims(static_cast<int32_t>(curve.coordinates.cols()));
  response->set_frames(static_cast<int32_t>(curve.coordinates.rows()));
  response->set_sample_rate(curve.sample_rate);
  AppendFloat32s(curve.coordinates.data(), curve.coordinates.size(),
                 response->mutable_coordinates());
  response->set_first_frame(curve.frames.first);
  response->set_last_frame(curve.frames.last);
}

void ToProto(const SpacePage& page, v1::ListSpacesResponse* response) {
  for (const auto& snapshot : page.spaces) ToProto(*snapshot, response->add_spaces());
  response->set_next_page_token(page.next_page_token);
}

}  // namespace motiondb::server
