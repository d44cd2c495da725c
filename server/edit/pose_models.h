// EditService's pose detection (thesis 3.4): Mixture-of-Gaussians models fitted to example
// poses (stored clips' frames or ranges) in a truncated space, kept by name in the database, and
// run over any clip of the space's skeleton as a log-likelihood curve with the intervals where
// it reaches the threshold.
#ifndef MOTIONDB_SERVER_EDIT_POSE_MODELS_H_
#define MOTIONDB_SERVER_EDIT_POSE_MODELS_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/ops/pose_detection.h"
#include "core/ops/pose_model.h"
#include "server/edit/context.h"

namespace motiondb::server {

struct PoseModelRequest {
  std::string name;  // unique among pose models; printable, 1 to 128 bytes
  std::string space;
  // Every frame of each (at the space rate) is a pose; each range is a group of FitPoseModel's
  // threshold.
  std::vector<ClipSelection> examples{};
  PoseModelOptions options{};
  std::string parameters_json{};  // stored with the model: how it was fitted
};

struct StoredPoseModel {
  storage::PoseModelRecord record;  // without its data
  PoseModel model;
};

struct DetectRequest {
  std::string model;
  ClipSelection clip;
  std::optional<double> threshold{};  // unset: the model's
  // Shortest interval reported, seconds from 0 to kMaxMinFrames frames at the space rate.
  double min_duration_s = 0.0;
};

// An interval where the clip holds the pose, at the clip's own rate.
struct DetectedRange {
  int first_frame = 0;
  int last_frame = 0;
  double start_s = 0.0;
  double end_s = 0.0;
  int peak_frame = 0;
  double peak = 0.0;  // the log-likelihood at peak_frame
};

struct DetectOutcome {
  std::string space;
  FrameRange frames;               // the range scored, at the clip's rate
  double sample_rate = 0.0;        // of the curve
  Eigen::VectorXd log_likelihood;  // per frame of the range at the space rate
  double threshold = 0.0;
  std::vector<DetectedRange> intervals{};
};

// ALREADY_EXISTS for a taken name; NOT_FOUND for an unknown space or clip; INVALID_ARGUMENT
// naming name, examples[i], or the option (components, dims, ...). Nothing is stored on error.
absl::StatusOr<StoredPoseModel> CreatePoseModel(const EditContext& context,
                                                const PoseModelRequest& request,
                                                const std::function<bool()>& should_stop);
// By name; only those of `space` when it is not empty (NOT_FOUND for an unknown space).
absl::StatusOr<std::vector<StoredPoseModel>> ListPoseModels(const EditContext& context,
                                                            const std::string& space);
// NOT_FOUND for an unknown model.
absl::Status DeletePoseModel(const EditContext& context, const std::string& name,
                             const std::function<bool()>& should_stop);
// NOT_FOUND for an unknown model or clip (or a model whose space is gone); FAILED_PRECONDITION
// for a clip of another skeleton; INVALID_ARGUMENT naming clip, threshold or min_duration_s;
// CANCELLED once `should_stop` says stop.
absl::StatusOr<DetectOutcome> DetectPose(const EditContext& context, const DetectRequest& request,
                                         const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_POSE_MODELS_H_
