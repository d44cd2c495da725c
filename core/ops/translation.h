// Translating a motion's curve (thesis 5.4): every point moved by one vector, which makes the
// poses more (or less) like another while keeping their relative positions, and so the
// motion's character. Toward a target pose, the vector runs from the selection's projected
// mean to the target (fig. 5.4: a sneak translated toward "hands up"); along an axis between
// two poses, it is the axis itself, so that clips move in parallel along a continuum and keep
// their incidental features. The caller gates and restricts the result with an EditScope.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_TRANSLATION_H_
#define MOTIONDB_CORE_OPS_TRANSLATION_H_

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/ops/edit_scope.h"

namespace motiondb {

enum class TranslateMode {
  kTowardPose,  // by amount x (target - the selection's mean)
  kAlongAxis,   // by amount x (axis_to - axis_from)
};

struct TranslateOptions {
  TranslateMode mode = TranslateMode::kTowardPose;
  // How far: 1 takes the selection's mean onto the target (or moves by the whole axis), 0.5
  // halfway, a negative amount away. Finite, in [-100, 100].
  double amount = 0.5;
  // The gate, which also weighs the selection's mean, and the dimensions moved.
  EditScope scope{};
};

// `curve`: frames x dims at `rate`; `poses`: the target (1 x dims) or the axis's two ends
// (2 x dims: from, to). INVALID_ARGUMENT naming amount, poses or the scope's fields.
absl::StatusOr<RowMatrixXd> TranslateCurve(const Eigen::Ref<const RowMatrixXd>& curve, double rate,
                                           const Eigen::Ref<const RowMatrixXd>& poses,
                                           const TranslateOptions& options);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_TRANSLATION_H_
