#include "core/ops/pose_detection.h"

#include <algorithm>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"

namespace motiondb {

namespace {

// A block's frames x components x dims^2 (the terms of its likelihoods) between two polls of a
// stop function: about a millisecond's.
constexpr Eigen::Index kModelTermsPerStopPoll = Eigen::Index{1} << 20;

}  // namespace

absl::StatusOr<Detection> DetectPose(const PoseModel& model,
                                     const Eigen::Ref<const RowMatrixXd>& curve,
                                     const DetectionOptions& options,
                                     const std::function<bool()>& should_stop) {
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
  // Each frame's likelihood is its own: a block of frames at a time, asking `should_stop`
  // between blocks (a long take of a large model takes seconds).
  detection.log_likelihood.resize(curve.rows());
  const Eigen::Index block = std::max<Eigen::Index>(
      1, kModelTermsPerStopPoll / (model.weights.size() * model.dims * model.dims));
  for (Eigen::Index first = 0; first < curve.rows(); first += block) {
    if (should_stop && should_stop()) {
      return absl::CancelledError("pose detection was stopped by its caller");
    }
    const Eigen::Index rows = std::min(block, curve.rows() - first);
    detection.log_likelihood.segment(first, rows) =
        PoseLogLikelihood(model, curve.middleRows(first, rows));
  }
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
