// Argument checks the operators share; every error names the field.
#ifndef MOTIONDB_CORE_OPS_INTERNAL_OP_CHECKS_H_
#define MOTIONDB_CORE_OPS_INTERNAL_OP_CHECKS_H_

#include <Eigen/Core>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "core/motion/matrix.h"

namespace motiondb::ops_internal {

// INVALID_ARGUMENT "`field` = value is out of range; expected `range`".
absl::Status OutOfRange(absl::string_view field, double value, absl::string_view range);

// `value` finite and within [low, high].
absl::Status CheckBetween(absl::string_view field, double value, double low, double high);

// Points of a space with `dims` dimensions: at least `min_rows` rows, at most `dims` columns
// (exactly `dims` when `exact`), all finite.
absl::Status CheckPoints(absl::string_view field, const Eigen::Ref<const RowMatrixXd>& points,
                         int dims, int min_rows, bool exact);

}  // namespace motiondb::ops_internal

#endif  // MOTIONDB_CORE_OPS_INTERNAL_OP_CHECKS_H_
