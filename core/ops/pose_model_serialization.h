// The stored form of a PoseModel: JSON text holding every number at full precision, so that a
// parsed model scores exactly as the fitted one.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_POSE_MODEL_SERIALIZATION_H_
#define MOTIONDB_CORE_OPS_POSE_MODEL_SERIALIZATION_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/ops/pose_model.h"

namespace motiondb {

std::string SerializePoseModel(const PoseModel& model);
// INVALID_ARGUMENT for text that is not a model's JSON, or a model that ValidatePoseModel
// refuses.
absl::StatusOr<PoseModel> ParsePoseModel(absl::string_view json);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_POSE_MODEL_SERIALIZATION_H_
