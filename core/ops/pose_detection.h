// Pose detection over a motion (thesis 3.4, fig. 3.6): a pose model's log-likelihood at every
// frame of a curve, and the intervals where it reaches a threshold: where the motion assumes
// the modelled pose.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_POSE_DETECTION_H_
#define MOTIONDB_CORE_OPS_POSE_DETECTION_H_

#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/ops/pose_model.h"

namespace motiondb {

// The longest DetectionOptions::min_frames.
inline constexpr int kMaxMinFrames = 1000000;

struct DetectionOptions {
  // Log-likelihood a frame must reach, finite; nullopt: the model's own threshold.
  std::optional<double> threshold{};
  // Shortest interval reported, in frames of the curve, 1..kMaxMinFrames.
  int min_frames = 1;
};

// A run of frames at or above the threshold, with its most likely frame.
struct DetectedInterval {
  int first = 0;
  int last = 0;
  int peak_frame = 0;
  double peak = 0.0;  // the log-likelihood at peak_frame
};

struct Detection {
  Eigen::VectorXd log_likelihood;  // per frame
  double threshold = 0.0;          // as applied
  std::vector<DetectedInterval> intervals{};
};

// `curve`: frames x at least model.dims coordinates. INVALID_ARGUMENT naming threshold,
// min_frames or the curve; the model's own errors (ValidatePoseModel). `should_stop` is asked
// about every millisecond of scoring: CANCELLED once it says stop.
absl::StatusOr<Detection> DetectPose(const PoseModel& model,
                                     const Eigen::Ref<const RowMatrixXd>& curve,
                                     const DetectionOptions& options = {},
                                     const std::function<bool()>& should_stop = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_POSE_DETECTION_H_
