#include "core/space/joint_weights.h"

#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/space/heading.h"

namespace motiondb {
namespace {

absl::Status CheckWeight(absl::string_view joint, double weight) {
  if (!std::isfinite(weight) || weight <= 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("weight of joint '", joint, "' must be finite and positive, got ", weight));
  }
  return absl::OkStatus();
}

// Total bone length moved by each joint, without the root-to-pelvis placement offsets.
Eigen::VectorXd BoneLengthBelow(const Skeleton& skeleton) {
  const int pelvis = FindPelvis(skeleton);
  std::vector<bool> placement(skeleton.joint_count(), false);  // its offset is not a bone
  for (int j = pelvis; j >= 0; j = skeleton.joint(j).parent) placement[j] = true;
  Eigen::VectorXd length = Eigen::VectorXd::Zero(skeleton.joint_count());
  // Parents precede children, so a reverse sweep sees every subtree complete.
  for (int j = skeleton.joint_count() - 1; j >= 0; --j) {
    const Joint& joint = skeleton.joint(j);
    if (joint.end_site) length[j] += joint.end_site->norm();
    if (joint.parent >= 0) {
      length[joint.parent] += length[j] + (placement[j] ? 0.0 : joint.offset.norm());
    }
  }
  return length;
}

}  // namespace

absl::string_view WeightPresetName(WeightPreset preset) {
  return preset == WeightPreset::kMass ? "mass" : "uniform";
}

absl::StatusOr<WeightPreset> ParseWeightPreset(absl::string_view name) {
  if (name == "mass") return WeightPreset::kMass;
  if (name == "uniform") return WeightPreset::kUniform;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown weight preset '", name, "' (expected mass or uniform)"));
}

absl::StatusOr<Eigen::VectorXd> ComputeJointWeights(const Skeleton& skeleton,
                                                    const JointWeightOptions& options) {
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(skeleton.joint_count());
  if (options.preset == WeightPreset::kMass) {
    if (!(options.floor > 0.0 && options.floor <= 1.0)) {
      return absl::InvalidArgumentError(
          absl::StrCat("weight floor must be in (0, 1], got ", options.floor));
    }
    const Eigen::VectorXd length = BoneLengthBelow(skeleton);
    const double largest = length.maxCoeff();
    if (largest > 0.0) weights = (length / largest).cwiseMax(options.floor);
  }
  for (const auto& [name, weight] : options.overrides) {
    const int joint = skeleton.FindJoint(name);
    if (joint < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("weight given for unknown joint '", name, "'"));
    }
    if (absl::Status status = CheckWeight(name, weight); !status.ok()) return status;
    weights[joint] = weight;
  }
  return weights;
}

absl::StatusOr<std::map<std::string, double>> ParseWeightOverrides(absl::string_view json) {
  const nlohmann::json parsed = nlohmann::json::parse(json.begin(), json.end(), nullptr,
                                                      /*allow_exceptions=*/false);
  if (parsed.is_discarded()) return absl::InvalidArgumentError("joint weights: invalid JSON");
  if (!parsed.is_object()) {
    return absl::InvalidArgumentError(
        "joint weights: expected a JSON object {\"JointName\": weight, ...}");
  }
  std::map<std::string, double> overrides;
  for (const auto& [name, value] : parsed.items()) {
    if (!value.is_number()) {
      return absl::InvalidArgumentError(
          absl::StrCat("joint weights: weight of joint '", name, "' is missing or not a number"));
    }
    if (absl::Status status = CheckWeight(name, value.get<double>()); !status.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("joint weights: ", status.message()));
    }
    overrides[name] = value.get<double>();
  }
  return overrides;
}

}  // namespace motiondb
