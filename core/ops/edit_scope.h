// Where a geometric edit applies (thesis 5.3, fig. 5.2): a gating envelope over time, whose
// ramps keep the edited stretch from popping, and a choice of dimensions. Every curve edit
// (scaling, translation, smoothing) is applied as original + G(t) (edited - original) on the
// chosen dimensions.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_EDIT_SCOPE_H_
#define MOTIONDB_CORE_OPS_EDIT_SCOPE_H_

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"

namespace motiondb {

// The envelope G(t) of fig. 5.2: 0 up to start_s - lead_in_s, rising linearly to 1 at start_s,
// 1 through end_s, falling linearly to 0 at end_s + lead_out_s. Times in seconds from the
// curve's first frame; a ramp of length 0 is a step.
struct Gate {
  double start_s = 0.0;     // t0; finite
  double end_s = 0.0;       // t1; finite, at least start_s
  double lead_in_s = 0.0;   // finite, >= 0
  double lead_out_s = 0.0;  // finite, >= 0
};

struct EditScope {
  // The gating envelope; nullopt: the edit applies at full strength on every frame.
  std::optional<Gate> gate{};
  // The dimensions the edit may change, each in 0..dims-1; empty: every dimension.
  std::vector<int> dims{};
};

// INVALID_ARGUMENT naming the field (gate.start_s, dims[2], ...) for a bad scope in a space of
// `space_dims` dimensions.
absl::Status ValidateEditScope(const EditScope& scope, int space_dims);

// G(t) at `frames` frames sampled at `rate` frames per second from t = 0.
Eigen::VectorXd GateEnvelope(const Gate& gate, int frames, double rate);

// The envelope of the scope (all ones without a gate).
Eigen::VectorXd ScopeEnvelope(const EditScope& scope, int frames, double rate);

// original + G(t) (edited - original) on the scope's dimensions, original elsewhere; both
// frames x dims of one shape, sampled at `rate`. The scope must have been validated.
RowMatrixXd ApplyScope(const EditScope& scope, const Eigen::Ref<const RowMatrixXd>& original,
                       const Eigen::Ref<const RowMatrixXd>& edited, double rate);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_EDIT_SCOPE_H_
