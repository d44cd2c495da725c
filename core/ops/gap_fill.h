// Filling the gap between two clips (thesis 4.3): from the last pose P0 of the first clip to the
// first pose P1 of the second, the Hermite curve of eq. 4.4,
//   x(t) = P0 (2t^3 - 3t^2 + 1) + P1 (-2t^3 + 3t^2) + v (D0 (t^3 - 2t^2 + t) + D1 (t^3 - t^2)),
// whose end derivatives D0 and D1 are the clips' own velocities at the seams (finite
// differences, optionally after wavelet smoothing, since noise spoils them), so the motion
// keeps its momentum across the gap; v in [0, 1] damps the cubic part. The baseline is the
// straight line from P0 to P1.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_GAP_FILL_H_
#define MOTIONDB_CORE_OPS_GAP_FILL_H_

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/ops/reconstruction.h"
#include "core/ops/wavelet_smoothing.h"

namespace motiondb {

enum class GapMethod {
  kHermite,  // eq. 4.4
  kLinear,   // the baseline: a straight line, which loses the clips' momentum
};

// The longest gap GapFillOptions::frames may ask for.
inline constexpr int kMaxGapFrames = 100000;

struct GapFillOptions {
  // Frames between the clips' last and first frames, 1..kMaxGapFrames.
  int frames = 15;
  GapMethod method = GapMethod::kHermite;
  // v of eq. 4.4, in [0, 1]: 1 keeps the clips' velocities at the seams, 0 arrives at rest.
  double damping = 1.0;
  // Wavelet smoothing level (wavelet_smoothing.h) of each clip before its end velocity is
  // taken; 0: the raw finite difference.
  double derivative_smoothing = 0.0;
};

// x(t) of eq. 4.4 at each t (rows of the result), for points and derivatives of one size. D0
// and D1 are per unit of t.
RowMatrixXd HermiteCurve(const Eigen::Ref<const Eigen::RowVectorXd>& p0,
                         const Eigen::Ref<const Eigen::RowVectorXd>& p1,
                         const Eigen::Ref<const Eigen::RowVectorXd>& d0,
                         const Eigen::Ref<const Eigen::RowVectorXd>& d1, double damping,
                         const Eigen::Ref<const Eigen::VectorXd>& t);

enum class CurveEnd { kFirst, kLast };

// The velocity per frame at `end` of `curve` (frames x dims): the finite difference of its two
// end frames after `smoothing` of the curve continued past that end by odd reflection, so that
// smoothing keeps a straight line's slope at its end (a level beyond the continued curve's own,
// about log2 of twice the frames, flattens it to 0). 0 for a curve of one frame.
// INVALID_ARGUMENT naming level, or the curve for NaN values.
absl::StatusOr<Eigen::RowVectorXd> EndVelocity(const Eigen::Ref<const RowMatrixXd>& curve,
                                               const SmoothingOptions& smoothing, CurveEnd end);

// The options.frames poses between `before` (ending at P0) and `after` (starting at P1), both
// frames x dims at one rate, at t = k / (frames + 1) for k = 1..frames. A clip of one frame
// has no velocity: 0. INVALID_ARGUMENT naming frames, damping, derivative_smoothing, before
// or after.
absl::StatusOr<RowMatrixXd> FillGap(const Eigen::Ref<const RowMatrixXd>& before,
                                    const Eigen::Ref<const RowMatrixXd>& after,
                                    const GapFillOptions& options = {});

// The jump in joint angular velocity at frame `seam` of pose rotations (frames x 4 * joints)
// sampled at `rate`: per joint, |w(seam -> seam + 1) - w(seam - 1 -> seam)| in rad/s, w being
// the rotation vector of q_a^-1 q_b times the rate; mean and max over the joints. Zero when the
// seam lacks a frame on either side. How abruptly a transition starts or ends (4.3).
AngleError VelocityJump(const Eigen::Ref<const RowMatrixXd>& rotations, int seam, double rate);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_GAP_FILL_H_
