// Scaling a motion's curve (thesis 5.3): every point moved away from (or toward) a centre by a
// factor, which exaggerates (or subdues) what distinguishes the poses from the centre. About the
// origin, the training set's mean pose, as Blanz and Vetter caricature faces; about the
// selection's own projected mean (local scaling, fig. 5.3), which keeps a motion lying to one
// side of the origin in place. Optionally the factor depends on a point's distance d from the
// centre through a shifted, scaled sigmoid S(d), so that only the poses beyond a threshold
// change. The caller gates and restricts the result with an EditScope.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_SCALING_H_
#define MOTIONDB_CORE_OPS_SCALING_H_

#include <optional>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/ops/edit_scope.h"

namespace motiondb {

enum class ScaleCentre {
  kOrigin,         // the space's origin: the training set's mean pose
  kSelectionMean,  // the selection's projected mean, frames weighted by the gate's envelope
};

// S(d) = 1 / (1 + exp(-(d - threshold) / width)): about 0 below the threshold, 1 above it.
struct Sigmoid {
  double threshold = 1.0;  // distance in the space's units where S = 1/2; finite, >= 0
  double width = 0.1;      // how gradually S rises around it; finite, > 0
};

struct ScaleOptions {
  // s: > 1 exaggerates, < 1 subdues, 1 changes nothing. Finite, in [-100, 100].
  double factor = 1.5;
  ScaleCentre centre = ScaleCentre::kOrigin;
  // With a sigmoid, a point at distance d moves by the factor 1 + (s - 1) S(d); nullopt: s.
  std::optional<Sigmoid> sigmoid{};
  // The gate, which also weighs the selection's mean, and the dimensions scaled (and measured
  // for d).
  EditScope scope{};
};

// `curve`: frames x the space's dims at `rate` frames per second. Returns the edited curve,
// scope applied. INVALID_ARGUMENT naming factor, sigmoid.threshold, sigmoid.width or the
// scope's fields.
absl::StatusOr<RowMatrixXd> ScaleCurve(const Eigen::Ref<const RowMatrixXd>& curve, double rate,
                                       const ScaleOptions& options);

// S(d) for one distance.
double SigmoidAt(const Sigmoid& sigmoid, double distance);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_SCALING_H_
