#include "core/ops/edit_scope.h"

#include <cmath>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using ops_internal::CheckBetween;

absl::Status ValidateGate(const Gate& gate) {
  constexpr double kMax = std::numeric_limits<double>::max();
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("gate.start_s", gate.start_s, -kMax, kMax));
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("gate.end_s", gate.end_s, gate.start_s, kMax));
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("gate.lead_in_s", gate.lead_in_s, 0.0, kMax));
  return CheckBetween("gate.lead_out_s", gate.lead_out_s, 0.0, kMax);
}

// The rise of a ramp of `length` that ends (reaches 1) `before` seconds later: 1 at 0, 0 at
// `length` and beyond.
double Ramp(double before, double length) {
  if (before <= 0.0) return 1.0;
  if (before >= length) return 0.0;
  return 1.0 - before / length;
}

}  // namespace

absl::Status ValidateEditScope(const EditScope& scope, int space_dims) {
  if (scope.gate) MOTIONDB_RETURN_IF_ERROR(ValidateGate(*scope.gate));
  std::vector<bool> seen(space_dims, false);
  for (size_t i = 0; i < scope.dims.size(); ++i) {
    const int d = scope.dims[i];
    if (d < 0 || d >= space_dims) {
      return ops_internal::OutOfRange(absl::StrCat("dims[", i, "]"), d,
                                      absl::StrCat("0..", space_dims - 1, " (the space's)"));
    }
    if (seen[d]) {
      return absl::InvalidArgumentError(absl::StrCat("dims[", i, "]: dimension ", d, " repeats"));
    }
    seen[d] = true;
  }
  return absl::OkStatus();
}

Eigen::VectorXd GateEnvelope(const Gate& gate, int frames, double rate) {
  Eigen::VectorXd envelope(frames);
  for (int k = 0; k < frames; ++k) {
    const double t = k / rate;
    envelope[k] = t < gate.start_s ? Ramp(gate.start_s - t, gate.lead_in_s)
                  : t > gate.end_s ? Ramp(t - gate.end_s, gate.lead_out_s)
                                   : 1.0;
  }
  return envelope;
}

Eigen::VectorXd ScopeEnvelope(const EditScope& scope, int frames, double rate) {
  if (!scope.gate) return Eigen::VectorXd::Ones(frames);
  return GateEnvelope(*scope.gate, frames, rate);
}

RowMatrixXd ApplyScope(const EditScope& scope, const Eigen::Ref<const RowMatrixXd>& original,
                       const Eigen::Ref<const RowMatrixXd>& edited, double rate) {
  const Eigen::VectorXd envelope = ScopeEnvelope(scope, static_cast<int>(original.rows()), rate);
  RowMatrixXd result = original;
  const auto blend = [&](Eigen::Index d) {
    result.col(d) += envelope.cwiseProduct(edited.col(d) - original.col(d));
  };
  if (scope.dims.empty()) {
    for (Eigen::Index d = 0; d < original.cols(); ++d) blend(d);
  } else {
    for (const int d : scope.dims) blend(d);
  }
  return result;
}

}  // namespace motiondb
