#include "core/ops/translation.h"

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "core/ops/projected_mean.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

constexpr double kMaxAmount = 100.0;

}  // namespace

absl::StatusOr<RowMatrixXd> TranslateCurve(const Eigen::Ref<const RowMatrixXd>& curve, double rate,
                                           const Eigen::Ref<const RowMatrixXd>& poses,
                                           const TranslateOptions& options) {
  const int dims = static_cast<int>(curve.cols());
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("curve", curve, dims, 1, true));
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckBetween("amount", options.amount, -kMaxAmount, kMaxAmount));
  MOTIONDB_RETURN_IF_ERROR(ValidateEditScope(options.scope, dims));
  const int wanted = options.mode == TranslateMode::kTowardPose ? 1 : 2;
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("poses", poses, dims, wanted, true));
  if (poses.rows() != wanted) {
    return absl::InvalidArgumentError(
        absl::StrCat("poses: ", poses.rows(), " given; ",
                     wanted == 1 ? "a translation toward a pose takes one" : "an axis takes two"));
  }
  Eigen::RowVectorXd direction;
  if (options.mode == TranslateMode::kTowardPose) {
    MOTIONDB_ASSIGN_OR_RETURN(const Eigen::RowVectorXd mean,
                              SelectionMean(options.scope, curve, rate));
    direction = poses.row(0) - mean;
  } else {
    direction = poses.row(1) - poses.row(0);
  }
  RowMatrixXd moved = curve;
  moved.rowwise() += options.amount * direction;
  return ApplyScope(options.scope, curve, moved, rate);
}

}  // namespace motiondb
