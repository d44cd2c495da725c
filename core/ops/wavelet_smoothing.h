// Smoothing by the Haar wavelet at a continuous level (thesis 5.5.1). Each dimension of a curve
// is supersampled linearly to a power-of-two length N = 2^L, decomposed into averages and
// differences of adjacent samples, and reconstructed without its finest `level` levels of
// differences: what remains at level s is the mean of each block of 2^s samples, read at the
// curve's own frames by linear interpolation between block centres. A fractional level is the
// linear interpolation of its two neighbouring whole levels (after Finkelstein and Salesin),
// level 0 being the curve as it is, so that levels between 0 and 1 mix the curve with its first
// smoothing. Level L and beyond give every frame one value: the mean of the supersampled curve
// (the curve's mean when the frame count is a power of two).
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_WAVELET_SMOOTHING_H_
#define MOTIONDB_CORE_OPS_WAVELET_SMOOTHING_H_

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"

namespace motiondb {

inline constexpr double kMaxSmoothingLevel = 64.0;

struct SmoothingOptions {
  // Levels of detail removed, finite and in [0, kMaxSmoothingLevel]: 1 halves the resolution, 2
  // quarters it; past the curve's own levels (log2 of its supersampled length), the curve's mean.
  double level = 1.0;
};

// `curve`: frames x dims (any frames >= 1). INVALID_ARGUMENT naming level, or the curve for
// NaN values.
absl::StatusOr<RowMatrixXd> SmoothCurve(const Eigen::Ref<const RowMatrixXd>& curve,
                                        const SmoothingOptions& options = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_WAVELET_SMOOTHING_H_
