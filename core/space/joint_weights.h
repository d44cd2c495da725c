// Per-joint weights for weighted PCA (SPEC §3): how much a joint's rotation counts in the pose
// distance. The default approximates the body mass a joint moves by the total bone length below
// it; `uniform` counts every joint alike; any joint can be overridden by name.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_SPACE_JOINT_WEIGHTS_H_
#define MOTIONDB_CORE_SPACE_JOINT_WEIGHTS_H_

#include <map>
#include <string>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/skeleton.h"

namespace motiondb {

enum class WeightPreset {
  kMass,     // bone length under the joint, normalised to a maximum of 1, floored
  kUniform,  // 1 for every joint
};

struct JointWeightOptions {
  // The weight every joint starts from.
  WeightPreset preset = WeightPreset::kMass;
  // kMass only: the smallest weight as a fraction of the largest, so that a leaf whose End Site
  // has zero length still counts. In (0, 1].
  double floor = 0.05;
  // Final weights of named joints, replacing the preset's; each finite and positive.
  std::map<std::string, double> overrides;
};

// "mass" or "uniform".
absl::string_view WeightPresetName(WeightPreset preset);
absl::StatusOr<WeightPreset> ParseWeightPreset(absl::string_view name);

// One positive weight per joint of `skeleton`. Mass: for each joint, the length of the bones from
// it to its children and everything below (End Sites included), leaving out the offsets on the
// way from the root down to the pelvis (a placement, not a bone; see heading.h), divided by the
// largest such total; a skeleton with no bone length at all gets 1 everywhere. Errors name the
// unknown joint or the bad value.
absl::StatusOr<Eigen::VectorXd> ComputeJointWeights(const Skeleton& skeleton,
                                                    const JointWeightOptions& options = {});

// Parses overrides written as a JSON object {"JointName": weight, ...}. Errors say what is wrong
// (not an object, a value that is missing or not a number, non-positive); joint names are checked
// against a skeleton by ComputeJointWeights.
absl::StatusOr<std::map<std::string, double>> ParseWeightOverrides(absl::string_view json);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_JOINT_WEIGHTS_H_
