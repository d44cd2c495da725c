#include "core/ops/scaling.h"

#include <cmath>
#include <limits>

#include "core/ops/internal/op_checks.h"
#include "core/ops/projected_mean.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using ops_internal::CheckBetween;

constexpr double kMaxFactor = 100.0;

absl::Status CheckOptions(const ScaleOptions& options, int dims) {
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("factor", options.factor, -kMaxFactor, kMaxFactor));
  if (options.sigmoid) {
    constexpr double kMax = std::numeric_limits<double>::max();
    MOTIONDB_RETURN_IF_ERROR(
        CheckBetween("sigmoid.threshold", options.sigmoid->threshold, 0.0, kMax));
    MOTIONDB_RETURN_IF_ERROR(CheckBetween("sigmoid.width", options.sigmoid->width,
                                          std::numeric_limits<double>::min(), kMax));
  }
  return ValidateEditScope(options.scope, dims);
}

// The distance of `offset` over the scope's dimensions.
double ScopeNorm(const EditScope& scope, const Eigen::Ref<const Eigen::RowVectorXd>& offset) {
  if (scope.dims.empty()) return offset.norm();
  double squared = 0.0;
  for (const int d : scope.dims) squared += offset[d] * offset[d];
  return std::sqrt(squared);
}

}  // namespace

double SigmoidAt(const Sigmoid& sigmoid, double distance) {
  return 1.0 / (1.0 + std::exp(-(distance - sigmoid.threshold) / sigmoid.width));
}

absl::StatusOr<RowMatrixXd> ScaleCurve(const Eigen::Ref<const RowMatrixXd>& curve, double rate,
                                       const ScaleOptions& options) {
  const int dims = static_cast<int>(curve.cols());
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("curve", curve, dims, 1, true));
  MOTIONDB_RETURN_IF_ERROR(CheckOptions(options, dims));
  const int frames = static_cast<int>(curve.rows());
  Eigen::RowVectorXd centre = Eigen::RowVectorXd::Zero(dims);
  if (options.centre == ScaleCentre::kSelectionMean) {
    MOTIONDB_ASSIGN_OR_RETURN(centre, SelectionMean(options.scope, curve, rate));
  }
  RowMatrixXd scaled(frames, dims);
  for (int f = 0; f < frames; ++f) {
    const Eigen::RowVectorXd offset = curve.row(f) - centre;
    double factor = options.factor;
    if (options.sigmoid) {
      factor = 1.0 + (options.factor - 1.0) *
                         SigmoidAt(*options.sigmoid, ScopeNorm(options.scope, offset));
    }
    scaled.row(f) = centre + factor * offset;
  }
  return ApplyScope(options.scope, curve, scaled, rate);
}

}  // namespace motiondb
