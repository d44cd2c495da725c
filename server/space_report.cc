#include "server/space_report.h"

#include <cmath>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "absl/strings/numbers.h"
#include "core/space/heading.h"

namespace motiondb::server {
namespace {

using Json = nlohmann::ordered_json;

constexpr const char* kMetricNames[] = {"SPACE_METRIC_UNIT", "SPACE_METRIC_EIGENVALUE_SCALED"};
constexpr const char* kPresetNames[] = {"WEIGHT_PRESET_MASS", "WEIGHT_PRESET_UNIFORM"};

const char* MetricName(SpaceMetric metric) {
  return kMetricNames[metric == SpaceMetric::kUnit ? 0 : 1];
}
const char* PresetName(WeightPreset preset) {
  return kPresetNames[preset == WeightPreset::kMass ? 0 : 1];
}

// The protobuf JSON mapping writes int64 as a string and non-finite doubles by name.
Json Int64(int64_t value) { return std::to_string(value); }
Json Double(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "Infinity" : "-Infinity";
  return value;
}

// Readers accept what the mapping accepts: numbers, or numbers written as strings.
std::optional<double> ReadDouble(const Json& json) {
  if (json.is_number()) return json.get<double>();
  if (!json.is_string()) return std::nullopt;
  const std::string text = json.get<std::string>();
  if (text == "NaN") return std::numeric_limits<double>::quiet_NaN();
  if (text == "Infinity") return std::numeric_limits<double>::infinity();
  if (text == "-Infinity") return -std::numeric_limits<double>::infinity();
  double value = 0;
  if (!absl::SimpleAtod(text, &value)) return std::nullopt;
  return value;
}
std::optional<int64_t> ReadInt(const Json& json) {
  if (json.is_number_integer()) return json.get<int64_t>();
  int64_t value = 0;
  if (json.is_string() && absl::SimpleAtoi(json.get<std::string>(), &value)) return value;
  return std::nullopt;
}

// Reads the report's fields; throws nlohmann::json::exception (or returns false) on a field of
// the wrong type.
bool ReadReport(const Json& json, SpaceReport& report) {
  bool ok = true;
  auto number = [&](const char* key, auto& out) {
    if (!json.contains(key)) return;
    using T = std::decay_t<decltype(out)>;
    if constexpr (std::is_floating_point_v<T>) {
      const std::optional<double> value = ReadDouble(json[key]);
      ok = ok && value.has_value();
      if (value) out = *value;
    } else {
      const std::optional<int64_t> value = ReadInt(json[key]);
      ok = ok && value.has_value();
      if (value) out = static_cast<T>(*value);
    }
  };
  number("dims", report.dims);
  number("joint_count", report.joint_count);
  if (json.contains("pelvis")) report.pelvis = json["pelvis"].get<std::string>();
  number("sample_rate", report.sample_rate);
  if (json.contains("heading_removed"))
    report.heading_removed = json["heading_removed"].get<bool>();
  number("yaw_rate_weight", report.yaw_rate_weight);
  number("root_velocity_weight", report.root_velocity_weight);
  if (json.contains("metric")) {
    report.metric = json["metric"] == kMetricNames[1] || json["metric"] == 2
                        ? SpaceMetric::kEigenvalueScaled
                        : SpaceMetric::kUnit;
  }
  if (json.contains("weight_preset")) {
    report.weight_preset = json["weight_preset"] == kPresetNames[1] || json["weight_preset"] == 2
                               ? WeightPreset::kUniform
                               : WeightPreset::kMass;
  }
  for (const Json& weight : json.value("joint_weights", Json::array())) {
    JointWeightReport& out = report.joint_weights.emplace_back();
    out.joint = weight.value("joint", "");
    out.weight = ReadDouble(weight.value("weight", Json(0))).value_or(0);
  }
  for (const Json& range : json.value("training", Json::array())) {
    TrainingReport& out = report.training.emplace_back();
    out.clip_id = ReadInt(range.value("clip_id", Json(0))).value_or(0);
    out.frames.first = static_cast<int>(ReadInt(range.value("first_frame", Json(0))).value_or(0));
    out.frames.last = static_cast<int>(ReadInt(range.value("last_frame", Json(0))).value_or(0));
  }
  number("training_frames", report.training_frames);
  for (const Json& value : json.value("explained_variance", Json::array())) {
    report.explained_variance.push_back(ReadDouble(value).value_or(0));
  }
  for (const Json& error : json.value("reconstruction_error", Json::array())) {
    ReconstructionError& out = report.reconstruction_error.emplace_back();
    out.dims = static_cast<int>(ReadInt(error.value("dims", Json(0))).value_or(0));
    out.mean_rad = ReadDouble(error.value("mean_rad", Json(0))).value_or(0);
    out.max_rad = ReadDouble(error.value("max_rad", Json(0))).value_or(0);
  }
  number("projected_clips", report.projected_clips);
  if (json.contains("learned_metric")) {  // reports before it have none
    const Json& learned = json.at("learned_metric");
    report.learned_metric_shrink = ReadDouble(learned.value("shrink", Json(0))).value_or(0);
    report.learned_metric_examples = ReadInt(learned.value("examples", Json(0))).value_or(0);
    report.learned_metric_descriptors = ReadInt(learned.value("descriptors", Json(0))).value_or(0);
  }
  number("build_ms", report.build_ms);
  return ok;
}

}  // namespace

SpaceReport DescribeSpace(const MotionSpace& space) {
  const SpaceData& data = space.data();
  SpaceReport report;
  report.dims = space.dims();
  report.joint_count = space.part_count();
  report.pelvis = space.skeleton().joint(FindPelvis(space.skeleton())).name;
  report.sample_rate = space.sample_rate();
  report.heading_removed = data.pose.remove_heading;
  report.yaw_rate_weight = data.pose.remove_heading ? data.yaw_rate_weight : 0.0;
  report.root_velocity_weight = data.root_velocity_weight;
  report.metric = data.metric;
  for (int j = 0; j < space.part_count(); ++j) {
    report.joint_weights.push_back({space.part_name(j), data.joint_weights[j]});
  }
  const Eigen::VectorXd explained = space.ExplainedVariance();
  report.explained_variance.assign(explained.data(), explained.data() + explained.size());
  return report;
}

std::string ReportToJson(const SpaceReport& report) {
  Json json;
  json["dims"] = report.dims;
  json["joint_count"] = report.joint_count;
  json["pelvis"] = report.pelvis;
  json["sample_rate"] = Double(report.sample_rate);
  json["heading_removed"] = report.heading_removed;
  json["yaw_rate_weight"] = Double(report.yaw_rate_weight);
  json["root_velocity_weight"] = Double(report.root_velocity_weight);
  json["metric"] = MetricName(report.metric);
  json["weight_preset"] = PresetName(report.weight_preset);
  json["joint_weights"] = Json::array();
  for (const JointWeightReport& weight : report.joint_weights) {
    json["joint_weights"].push_back({{"joint", weight.joint}, {"weight", Double(weight.weight)}});
  }
  json["training"] = Json::array();
  for (const TrainingReport& range : report.training) {
    json["training"].push_back({{"clip_id", Int64(range.clip_id)},
                                {"first_frame", range.frames.first},
                                {"last_frame", range.frames.last}});
  }
  json["training_frames"] = Int64(report.training_frames);
  json["explained_variance"] = Json::array();
  for (const double value : report.explained_variance) {
    json["explained_variance"].push_back(Double(value));
  }
  json["reconstruction_error"] = Json::array();
  for (const ReconstructionError& error : report.reconstruction_error) {
    json["reconstruction_error"].push_back({{"dims", error.dims},
                                            {"mean_rad", Double(error.mean_rad)},
                                            {"max_rad", Double(error.max_rad)}});
  }
  json["projected_clips"] = Int64(report.projected_clips);
  if (report.learned_metric_examples > 0) {
    json["learned_metric"] = {{"shrink", Double(report.learned_metric_shrink)},
                              {"examples", Int64(report.learned_metric_examples)},
                              {"descriptors", Int64(report.learned_metric_descriptors)}};
  }
  json["build_ms"] = Double(report.build_ms);
  return json.dump();
}

SpaceReport ReportFromJson(const std::string& json, const MotionSpace& space) {
  const Json parsed = Json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (!parsed.is_object()) return DescribeSpace(space);
  SpaceReport report;
  try {
    if (ReadReport(parsed, report)) return report;
  } catch (const nlohmann::json::exception&) {
    // A field of the wrong type: as unreadable as no report at all.
  }
  return DescribeSpace(space);
}

}  // namespace motiondb::server
