#include "core/ops/projected_mean.h"

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<Eigen::RowVectorXd> ProjectedMean(const Eigen::Ref<const RowMatrixXd>& points,
                                                 const Eigen::Ref<const Eigen::VectorXd>& weights) {
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints(
      "points", points, static_cast<int>(points.cols()), 1, /*exact=*/true));
  if (weights.size() == 0) return Eigen::RowVectorXd(points.colwise().mean());
  if (weights.size() != points.rows()) {
    return absl::InvalidArgumentError(
        absl::StrCat("weights: ", weights.size(), " given for ", points.rows(), " points"));
  }
  if (!weights.allFinite() || (weights.array() < 0.0).any() || weights.sum() <= 0.0) {
    return absl::InvalidArgumentError("weights: each must be finite and >= 0, and not all 0");
  }
  return Eigen::RowVectorXd(weights.transpose() * points / weights.sum());
}

absl::StatusOr<Eigen::RowVectorXd> SelectionMean(const EditScope& scope,
                                                 const Eigen::Ref<const RowMatrixXd>& curve,
                                                 double rate) {
  const Eigen::VectorXd envelope = ScopeEnvelope(scope, static_cast<int>(curve.rows()), rate);
  if (envelope.sum() <= 0.0) {
    return absl::InvalidArgumentError(absl::StrCat("gate: selects no frame of the ", curve.rows(),
                                                   " frames (", curve.rows() / rate, " s) edited"));
  }
  return ProjectedMean(curve, envelope);
}

}  // namespace motiondb
