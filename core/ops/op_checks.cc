#include "core/ops/internal/op_checks.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace motiondb::ops_internal {

absl::Status OutOfRange(absl::string_view field, double value, absl::string_view range) {
  return absl::InvalidArgumentError(
      absl::StrCat(field, " = ", value, " is out of range; expected ", range));
}

absl::Status CheckBetween(absl::string_view field, double value, double low, double high) {
  if (!std::isfinite(value) || value < low || value > high) {
    return OutOfRange(field, value, absl::StrCat(low, "..", high));
  }
  return absl::OkStatus();
}

absl::Status CheckPoints(absl::string_view field, const Eigen::Ref<const RowMatrixXd>& points,
                         int dims, int min_rows, bool exact) {
  if (points.rows() < min_rows) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": ", points.rows(), " poses given, at least ", min_rows, " needed"));
  }
  if (points.cols() > dims || (exact && points.cols() != dims)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": points have ", points.cols(), " coordinates, the space has ", dims));
  }
  if (!points.allFinite()) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": NaN or infinite coordinates"));
  }
  return absl::OkStatus();
}

}  // namespace motiondb::ops_internal
