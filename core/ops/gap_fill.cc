#include "core/ops/gap_fill.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "core/ops/internal/quat_rows.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// The angular velocity of one joint from frame f to f + 1, per frame.
Eigen::Vector3d Step(const Eigen::Ref<const RowMatrixXd>& rotations, Eigen::Index f,
                     Eigen::Index j) {
  return LogMap(ops_internal::QuatAt(rotations, f, 4 * j).conjugate() *
                ops_internal::QuatAt(rotations, f + 1, 4 * j));
}

}  // namespace

absl::StatusOr<Eigen::RowVectorXd> EndVelocity(const Eigen::Ref<const RowMatrixXd>& curve,
                                               const SmoothingOptions& smoothing, CurveEnd end) {
  const Eigen::Index n = curve.rows();
  if (n < 2) return Eigen::RowVectorXd::Zero(curve.cols()).eval();
  // The curve runs towards its end, then on past it by odd reflection about the end sample,
  // x(end + k) = 2 x(end) - x(end - k). Smoothed as it is, the end would be a block's edge and
  // the last block's mean would flatten it; continued, a straight line stays straight through
  // the end, and the reflection's symmetry keeps the smoothed end at the end sample.
  const RowMatrixXd toward =
      end == CurveEnd::kLast ? RowMatrixXd(curve) : RowMatrixXd(curve.colwise().reverse());
  RowMatrixXd continued(2 * n - 1, curve.cols());
  continued.topRows(n) = toward;
  for (Eigen::Index k = 1; k < n; ++k) {
    continued.row(n - 1 + k) = 2.0 * toward.row(n - 1) - toward.row(n - 1 - k);
  }
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd smooth, SmoothCurve(continued, smoothing));
  const Eigen::RowVectorXd velocity = smooth.row(n - 1) - smooth.row(n - 2);
  return end == CurveEnd::kLast ? velocity : Eigen::RowVectorXd(-velocity);
}

AngleError VelocityJump(const Eigen::Ref<const RowMatrixXd>& rotations, int seam, double rate) {
  AngleError jump;
  const Eigen::Index joints = rotations.cols() / 4;
  if (seam < 1 || seam + 1 >= rotations.rows() || joints == 0) return jump;
  for (Eigen::Index j = 0; j < joints; ++j) {
    const double change = (Step(rotations, seam, j) - Step(rotations, seam - 1, j)).norm() * rate;
    jump.mean_rad += change;
    jump.max_rad = std::max(jump.max_rad, change);
  }
  jump.mean_rad /= static_cast<double>(joints);
  return jump;
}

RowMatrixXd HermiteCurve(const Eigen::Ref<const Eigen::RowVectorXd>& p0,
                         const Eigen::Ref<const Eigen::RowVectorXd>& p1,
                         const Eigen::Ref<const Eigen::RowVectorXd>& d0,
                         const Eigen::Ref<const Eigen::RowVectorXd>& d1, double damping,
                         const Eigen::Ref<const Eigen::VectorXd>& t) {
  RowMatrixXd curve(t.size(), p0.size());
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    const double s = t[k];
    const double s2 = s * s;
    const double s3 = s2 * s;
    curve.row(k) = p0 * (2 * s3 - 3 * s2 + 1) + p1 * (-2 * s3 + 3 * s2) +
                   damping * (d0 * (s3 - 2 * s2 + s) + d1 * (s3 - s2));
  }
  return curve;
}

absl::StatusOr<RowMatrixXd> FillGap(const Eigen::Ref<const RowMatrixXd>& before,
                                    const Eigen::Ref<const RowMatrixXd>& after,
                                    const GapFillOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckBetween("frames", options.frames, 1, kMaxGapFrames));
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckBetween("damping", options.damping, 0.0, 1.0));
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckBetween(
      "derivative_smoothing", options.derivative_smoothing, 0.0, kMaxSmoothingLevel));
  const int dims = static_cast<int>(before.cols());
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("before", before, dims, 1, true));
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("after", after, dims, 1, true));
  const int steps = options.frames + 1;  // from P0 to P1 in frame steps
  Eigen::VectorXd t(options.frames);
  for (int k = 0; k < options.frames; ++k) t[k] = static_cast<double>(k + 1) / steps;
  const Eigen::RowVectorXd p0 = before.row(before.rows() - 1);
  const Eigen::RowVectorXd p1 = after.row(0);
  if (options.method == GapMethod::kLinear) {
    RowMatrixXd line(options.frames, dims);
    for (int k = 0; k < options.frames; ++k) line.row(k) = (1.0 - t[k]) * p0 + t[k] * p1;
    return line;
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const Eigen::RowVectorXd d0,
      EndVelocity(before, {.level = options.derivative_smoothing}, CurveEnd::kLast));
  MOTIONDB_ASSIGN_OR_RETURN(
      const Eigen::RowVectorXd d1,
      EndVelocity(after, {.level = options.derivative_smoothing}, CurveEnd::kFirst));
  // Per frame to per unit of t, which spans `steps` frames.
  return HermiteCurve(p0, p1, d0 * steps, d1 * steps, options.damping, t);
}

}  // namespace motiondb
