#include "server/space_report.h"

#include <google/protobuf/util/json_util.h>

#include "core/space/heading.h"

namespace motiondb::server {

v1::SpaceMetric ToProto(SpaceMetric metric) {
  return metric == SpaceMetric::kUnit ? v1::SPACE_METRIC_UNIT : v1::SPACE_METRIC_EIGENVALUE_SCALED;
}

v1::WeightPreset ToProto(WeightPreset preset) {
  return preset == WeightPreset::kMass ? v1::WEIGHT_PRESET_MASS : v1::WEIGHT_PRESET_UNIFORM;
}

v1::SpaceBuildReport DescribeSpace(const MotionSpace& space) {
  const SpaceData& data = space.data();
  v1::SpaceBuildReport report;
  report.set_dims(space.dims());
  report.set_joint_count(space.skeleton().joint_count());
  report.set_pelvis(space.skeleton().joint(FindPelvis(space.skeleton())).name);
  report.set_sample_rate(space.sample_rate());
  report.set_heading_removed(data.pose.remove_heading);
  report.set_yaw_rate_weight(data.pose.remove_heading ? data.yaw_rate_weight : 0.0);
  report.set_metric(ToProto(data.metric));
  for (int j = 0; j < space.skeleton().joint_count(); ++j) {
    v1::JointWeight* weight = report.add_joint_weights();
    weight->set_joint(space.skeleton().joint(j).name);
    weight->set_weight(data.joint_weights[j]);
  }
  const Eigen::VectorXd explained = space.ExplainedVariance();
  for (int i = 0; i < explained.size(); ++i) report.add_explained_variance(explained[i]);
  return report;
}

void AddReconstructionErrors(const std::vector<ReconstructionError>& errors,
                             v1::SpaceBuildReport* report) {
  for (const ReconstructionError& error : errors) {
    v1::ReconstructionError* out = report->add_reconstruction_error();
    out->set_dims(error.dims);
    out->set_mean_rad(error.mean_rad);
    out->set_max_rad(error.max_rad);
  }
}

std::string ReportToJson(const v1::SpaceBuildReport& report) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string json;
  // Printing a message of a compiled-in type cannot fail.
  (void)google::protobuf::util::MessageToJsonString(report, &json, options);
  return json;
}

v1::SpaceBuildReport ReportFromJson(const std::string& json, const MotionSpace& space) {
  v1::SpaceBuildReport report;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = true;  // a report written by a later version
  if (json.empty() || !google::protobuf::util::JsonStringToMessage(json, &report, options).ok()) {
    return DescribeSpace(space);
  }
  return report;
}

void FillSpaceIndex(const SpaceSnapshot& snapshot, v1::SpaceIndex* index) {
  index->set_dims(snapshot.space->dims());
  if (!snapshot.index) return;
  index->set_clips(snapshot.index->clip_count());
  index->set_frames(snapshot.index->total_frames());
  index->set_ann_dims(snapshot.index->ann_dims());
  index->set_coordinate_bytes(snapshot.coordinate_bytes());
  index->set_tree_bytes(snapshot.tree_bytes());
}

void FillSpace(const SpaceSnapshot& snapshot, v1::Space* space) {
  const storage::SpaceRecord& record = snapshot.record;
  space->set_space_id(record.space_id);
  space->set_name(record.name);
  space->set_skeleton_id(record.skeleton_id);
  space->set_version(record.version);
  space->set_created_unix_ms(record.created_unix_ms);
  *space->mutable_report() = ReportFromJson(record.build_report_json, *snapshot.space);
  FillSpaceIndex(snapshot, space->mutable_index());
}

}  // namespace motiondb::server
