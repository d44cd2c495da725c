#include "server/edit/curves.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "server/edit/internal/request_fields.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// The edit of a curve at `rate` under `scope` (its gate in seconds from the range's start),
// adding to `sources` the ranges it reads besides the curve's.
using CurveFunction = std::function<absl::StatusOr<RowMatrixXd>(
    const SpaceSnapshot& snapshot, const RowMatrixXd& curve, const EditScope& scope, double rate,
    std::vector<SourceRange>& sources)>;

// The scope with its gate moved from the clip's time to the range's.
EditScope RangeScope(const EditScope& scope, const EditSource& source) {
  EditScope shifted = scope;
  if (shifted.gate) {
    const double start = source.range.frames.first / source.fps;
    shifted.gate->start_s -= start;
    shifted.gate->end_s -= start;
  }
  return shifted;
}

absl::StatusOr<EditResult> EditInSpace(const EditContext& context, const CurveEdit& edit,
                                       const std::string& op, const CurveFunction& function,
                                       const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(context.registry, edit.space));
  const MotionSpace& space = *snapshot->space;
  MOTIONDB_RETURN_IF_ERROR(ValidateEditScope(edit.scope, space.dims()));
  MOTIONDB_RETURN_IF_ERROR(ValidateJointConstraints(space, edit.constraints));
  MOTIONDB_ASSIGN_OR_RETURN(const SourceShape shape,
                            ShapeOf(context.database, *snapshot, edit.clip, "clip"));
  // The sources: the clip's range, and a translation's poses (at most two).
  MOTIONDB_RETURN_IF_ERROR(CheckEditAnswer(context, space, shape,
                                           {.space_frames = shape.space_frames, .sources = 3},
                                           edit.output, "ask for a shorter range of the clip"));
  MOTIONDB_ASSIGN_OR_RETURN(const EditSource source, LoadSource(context.database, *snapshot,
                                                                edit.clip, "clip", should_stop));
  Provenance provenance{op, edit.space, {source.range}};
  MOTIONDB_ASSIGN_OR_RETURN(
      const RowMatrixXd curve,
      function(*snapshot, source.motion.coordinates, RangeScope(edit.scope, source),
               space.sample_rate(), provenance.sources));
  EditedMotion edited{RowMatrixXd(), source.motion.placement};
  MOTIONDB_RETURN_IF_ERROR(CheckEditStop(should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(edited.rotations, space.Reconstruct(curve, should_stop));
  MOTIONDB_RETURN_IF_ERROR(
      ApplyJointConstraints(space, edit.constraints, source.motion.rotations, &edited.rotations));
  return FinishEdit(context, space, source, edited, std::move(provenance), edit.output,
                    should_stop);
}

// EditInSpace with its errors in the request's fields: the operators see the scope and the
// constraints as their own options and the clip's range as their curve; `more` names the
// edit's own.
absl::StatusOr<EditResult> RunCurveEdit(const EditContext& context, const CurveEdit& edit,
                                        const std::string& op, const CurveFunction& function,
                                        const std::function<bool()>& should_stop,
                                        RequestFields more = {}) {
  more.insert(more.end(), {{"gate", "scope.gate"},
                           {"dims", "scope.dims"},
                           {"edit_weights", "constraints.edit_weights"},
                           {"max_angles", "constraints.max_angles"},
                           {"source_margin", "constraints.source_margin"},
                           {"curve", "clip"}});
  return InRequestFields(EditInSpace(context, edit, op, function, should_stop), more);
}

}  // namespace

absl::StatusOr<EditResult> Scale(const EditContext& context, const ScaleRequest& request,
                                 const std::function<bool()>& should_stop) {
  return RunCurveEdit(
      context, request.edit, "scale",
      [&](const SpaceSnapshot&, const RowMatrixXd& curve, const EditScope& scope, double rate,
          std::vector<SourceRange>&) {
        ScaleOptions options = request.options;
        options.scope = scope;
        return ScaleCurve(curve, rate, options);
      },
      should_stop);
}

absl::StatusOr<EditResult> Translate(const EditContext& context, const TranslateRequest& request,
                                     const std::function<bool()>& should_stop) {
  // The request's fields for its poses, as many as the mode takes (the operator checks that).
  const bool toward = request.options.mode == TranslateMode::kTowardPose;
  std::vector<std::string> pose_fields = toward ? std::vector<std::string>{"target"}
                                                : std::vector<std::string>{"axis_from", "axis_to"};
  for (size_t i = pose_fields.size(); i < request.poses.size(); ++i) {
    pose_fields.push_back(absl::StrCat("poses[", i, "]"));
  }
  return RunCurveEdit(
      context, request.edit, "translate",
      [&](const SpaceSnapshot& snapshot, const RowMatrixXd& curve, const EditScope& scope,
          double rate, std::vector<SourceRange>& sources) -> absl::StatusOr<RowMatrixXd> {
        RowMatrixXd poses(request.poses.size(), curve.cols());
        for (size_t i = 0; i < request.poses.size(); ++i) {
          MOTIONDB_ASSIGN_OR_RETURN(const EditSource source,
                                    LoadSource(context.database, snapshot, request.poses[i],
                                               pose_fields[i], should_stop));
          MOTIONDB_ASSIGN_OR_RETURN(const EditPose pose, PoseOf(*snapshot.space, source));
          poses.row(i) = pose.coordinates.row(0);
          sources.push_back(source.range);
        }
        TranslateOptions options = request.options;
        options.scope = scope;
        return TranslateCurve(curve, rate, poses, options);
      },
      should_stop, {{"poses", toward ? "target" : "axis_from and axis_to"}});
}

absl::StatusOr<EditResult> Smooth(const EditContext& context, const SmoothRequest& request,
                                  const std::function<bool()>& should_stop) {
  return RunCurveEdit(
      context, request.edit, "smooth",
      [&](const SpaceSnapshot&, const RowMatrixXd& curve, const EditScope& scope, double rate,
          std::vector<SourceRange>&) -> absl::StatusOr<RowMatrixXd> {
        MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd smoothed, SmoothCurve(curve, request.options));
        return ApplyScope(scope, curve, smoothed, rate);
      },
      should_stop);
}

}  // namespace motiondb::server
