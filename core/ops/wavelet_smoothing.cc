#include "core/ops/wavelet_smoothing.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// Row `position` (fractional) of `samples` by linear interpolation, clamped to its ends. A Ref,
// so that the curve is not copied whole for every row read (a `const RowMatrixXd&` made a
// temporary of the Ref'd curve at each call: 512 copies of the curve per smoothing).
Eigen::RowVectorXd ReadAt(const Eigen::Ref<const RowMatrixXd>& samples, double position) {
  const double last = static_cast<double>(samples.rows() - 1);
  position = std::clamp(position, 0.0, last);
  const Eigen::Index low = static_cast<Eigen::Index>(std::floor(position));
  const Eigen::Index high = std::min<Eigen::Index>(low + 1, samples.rows() - 1);
  const double fraction = position - static_cast<double>(low);
  return (1.0 - fraction) * samples.row(low) + fraction * samples.row(high);
}

// The Haar averages of every level: pyramid[s] holds N / 2^s block means of the supersampled
// curve, which is its reconstruction without the s finest levels of differences.
std::vector<RowMatrixXd> AveragePyramid(const Eigen::Ref<const RowMatrixXd>& curve) {
  const Eigen::Index n = curve.rows();
  Eigen::Index size = 1;
  while (size < n) size *= 2;
  RowMatrixXd supersampled(size, curve.cols());
  for (Eigen::Index j = 0; j < size; ++j) {
    const double position = size == 1 ? 0.0 : static_cast<double>(j) * (n - 1) / (size - 1);
    supersampled.row(j) = ReadAt(curve, position);
  }
  std::vector<RowMatrixXd> pyramid{std::move(supersampled)};
  while (pyramid.back().rows() > 1) {
    const RowMatrixXd& finer = pyramid.back();
    RowMatrixXd coarser(finer.rows() / 2, finer.cols());
    for (Eigen::Index b = 0; b < coarser.rows(); ++b) {
      coarser.row(b) = 0.5 * (finer.row(2 * b) + finer.row(2 * b + 1));
    }
    pyramid.push_back(std::move(coarser));
  }
  return pyramid;
}

// Level s of the pyramid read at the curve's own n frames.
RowMatrixXd LevelAtFrames(const std::vector<RowMatrixXd>& pyramid, int s, Eigen::Index n) {
  const double size = static_cast<double>(pyramid.front().rows());
  const double block = std::ldexp(1.0, s);
  RowMatrixXd result(n, pyramid.front().cols());
  for (Eigen::Index i = 0; i < n; ++i) {
    const double position = n == 1 ? 0.0 : static_cast<double>(i) * (size - 1) / (n - 1);
    result.row(i) = ReadAt(pyramid[s], (position + 0.5) / block - 0.5);
  }
  return result;
}

}  // namespace

absl::StatusOr<RowMatrixXd> SmoothCurve(const Eigen::Ref<const RowMatrixXd>& curve,
                                        const SmoothingOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckBetween("level", options.level, 0.0, kMaxSmoothingLevel));
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckPoints("curve", curve, static_cast<int>(curve.cols()), 1, true));
  if (options.level == 0.0) return RowMatrixXd(curve);
  const std::vector<RowMatrixXd> pyramid = AveragePyramid(curve);
  const int top = static_cast<int>(pyramid.size()) - 1;
  const double level = std::min(options.level, static_cast<double>(top));
  const int low = static_cast<int>(std::floor(level));
  const int high = std::min(low + 1, top);
  const double fraction = level - low;
  const Eigen::Index n = curve.rows();
  // Level 0 is the curve itself, not its supersampled pyramid read back: away from a power of
  // two the two differ by part of the curve's noise, which must not come back at any level.
  const auto at_level = [&](int s) {
    return s == 0 ? RowMatrixXd(curve) : LevelAtFrames(pyramid, s, n);
  };
  RowMatrixXd smoothed = (1.0 - fraction) * at_level(low);
  if (fraction > 0.0) smoothed += fraction * at_level(high);
  return smoothed;
}

}  // namespace motiondb
