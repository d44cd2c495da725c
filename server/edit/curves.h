// EditService's curve edits (thesis 5.3-5.5): scaling, translation and smoothing of a stored
// clip's range in a space, under a gate and on chosen dimensions, with joint limits and
// selective blending applied after unprojection (5.7).
#ifndef MOTIONDB_SERVER_EDIT_CURVES_H_
#define MOTIONDB_SERVER_EDIT_CURVES_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/ops/edit_scope.h"
#include "core/ops/joint_constraints.h"
#include "core/ops/scaling.h"
#include "core/ops/translation.h"
#include "core/ops/wavelet_smoothing.h"
#include "server/edit/context.h"

namespace motiondb::server {

// What every curve edit takes.
struct CurveEdit {
  std::string space;
  ClipSelection clip;
  // The gate's times are seconds from the clip's frame 0 (not from the range's first frame).
  EditScope scope{};
  JointConstraints constraints{};
  EditOutput output{};
};

struct ScaleRequest {
  CurveEdit edit;
  ScaleOptions options{};  // its scope is ignored: edit.scope applies
};

struct TranslateRequest {
  CurveEdit edit;
  // The target pose (kTowardPose), or the axis's two ends (kAlongAxis): each a frame, or the
  // projected mean of a range.
  std::vector<ClipSelection> poses{};
  TranslateOptions options{};  // its scope is ignored: edit.scope applies
};

struct SmoothRequest {
  CurveEdit edit;
  SmoothingOptions options{};
};

// NOT_FOUND for an unknown space or clip; INVALID_ARGUMENT naming the request's field (clip,
// target, axis_from, factor, scope.gate.start_s, scope.dims[0],
// constraints.edit_weights[Joint], ...); nothing is stored on error.
absl::StatusOr<EditResult> Scale(const EditContext& context, const ScaleRequest& request,
                                 const std::function<bool()>& should_stop);
absl::StatusOr<EditResult> Translate(const EditContext& context, const TranslateRequest& request,
                                     const std::function<bool()>& should_stop);
absl::StatusOr<EditResult> Smooth(const EditContext& context, const SmoothRequest& request,
                                  const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_CURVES_H_
