#include "core/ops/pose_detection.h"

#include <limits>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<Detection> DetectPose(const PoseModel& model,
                                     const Eigen::Ref<const RowMatrixXd>& curve,
                                     const DetectionOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(ValidatePoseModel(model));
  if (curve.cols() < model.dims) {
    return absl::InvalidArgumentError(
        absl::StrCat("curve: ", curve.cols(), " coordinates, the model needs ", model.dims));
  }
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckPoints("curve", curve, static_cast<int>(curve.cols()), 1, true));
  if (options.threshold) {
    constexpr double kMax = std::numeric_limits<double>::max();
    MOTIONDB_RETURN_IF_ERROR(
        ops_internal::CheckBetween("threshold", *options.threshold, -kMax, kMax));
  }
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckBetween("min_frames", options.min_frames, 1, kMaxMinFrames));
  Detection detection;
  detection.threshold = options.threshold.value_or(model.threshold);
  detection.log_likelihood = PoseLogLikelihood(model, curve);
  const int frames = static_cast<int>(curve.rows());
  for (int f = 0; f < frames;) {
    if (detection.log_likelihood[f] < detection.threshold) {
      ++f;
      continue;
    }
    DetectedInterval interval{f, f, f, detection.log_likelihood[f]};
    for (; f < frames && detection.log_likelihood[f] >= detection.threshold; ++f) {
      interval.last = f;
      if (detection.log_likelihood[f] > interval.peak) {
        interval.peak = detection.log_likelihood[f];
        interval.peak_frame = f;
      }
    }
    if (interval.last - interval.first + 1 >= options.min_frames) {
      detection.intervals.push_back(interval);
    }
  }
  return detection;
}

}  // namespace motiondb
