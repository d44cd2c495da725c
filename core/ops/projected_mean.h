// The projected mean of a selection of poses (thesis 5.2, eq. 5.1): the arithmetic mean of
// their points, which unprojects to an approximation of their quaternion mean pose. The
// reference point of local scaling and of translation.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_PROJECTED_MEAN_H_
#define MOTIONDB_CORE_OPS_PROJECTED_MEAN_H_

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/ops/edit_scope.h"

namespace motiondb {

// The mean of the rows of `points` (frames x dims), each weighted by `weights` (one per row,
// >= 0, not all 0; empty: all 1): a gated selection weighs its frames by the envelope.
// INVALID_ARGUMENT naming points or weights.
absl::StatusOr<Eigen::RowVectorXd> ProjectedMean(const Eigen::Ref<const RowMatrixXd>& points,
                                                 const Eigen::Ref<const Eigen::VectorXd>& weights);

// The mean of a curve sampled at `rate` over the scope's selection: its frames weighted by the
// gate's envelope (all alike without a gate). INVALID_ARGUMENT naming the gate when it selects
// no frame of the curve.
absl::StatusOr<Eigen::RowVectorXd> SelectionMean(const EditScope& scope,
                                                 const Eigen::Ref<const RowMatrixXd>& curve,
                                                 double rate);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_PROJECTED_MEAN_H_
