#include "server/edit/reconstruct.h"

#include "server/edit/internal/request_fields.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"

namespace motiondb::server {

namespace {

absl::StatusOr<ReconstructOutcome> Rebuild(const EditContext& context,
                                           const ReconstructRequest& request,
                                           const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(context.registry, request.space));
  const MotionSpace& space = *snapshot->space;
  MOTIONDB_ASSIGN_OR_RETURN(const SourceShape shape,
                            ShapeOf(context.database, *snapshot, request.clip, "clip"));
  // Each joint's error (its name and two numbers), and with error_curve one per dimension.
  int64_t extra = 0;
  for (const Joint& joint : shape.skeleton->joints()) {
    extra += TextFieldBytes(static_cast<int64_t>(joint.name.size())) + 2 * kNumberFieldBytes +
             kFieldFramingBytes;
  }
  if (request.options.error_curve) {
    extra += space.dims() * (3 * kNumberFieldBytes + kFieldFramingBytes);
  }
  MOTIONDB_RETURN_IF_ERROR(CheckEditAnswer(
      context, space, shape, {.space_frames = shape.space_frames, .extra_bytes = extra},
      request.output, "ask for a shorter range of the clip"));
  MOTIONDB_ASSIGN_OR_RETURN(const EditSource source, LoadSource(context.database, *snapshot,
                                                                request.clip, "clip", should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(
      Reconstruction rebuilt,
      motiondb::Reconstruct(space, source.motion.coordinates, source.motion.rotations,
                            request.options, should_stop));
  ReconstructOutcome outcome;
  outcome.dims = rebuilt.dims;
  outcome.overall = rebuilt.overall;
  outcome.curve = std::move(rebuilt.curve);
  for (size_t j = 0; j < rebuilt.joints.size(); ++j) {
    outcome.joints.push_back({space.skeleton().joint(static_cast<int>(j)).name, rebuilt.joints[j]});
  }
  const EditedMotion edited{std::move(rebuilt.rotations), source.motion.placement};
  MOTIONDB_ASSIGN_OR_RETURN(
      outcome.result,
      FinishEdit(context, space, source, edited, {"reconstruct", request.space, {source.range}},
                 request.output, should_stop));
  return outcome;
}

}  // namespace

absl::StatusOr<ReconstructOutcome> Reconstruct(const EditContext& context,
                                               const ReconstructRequest& request,
                                               const std::function<bool()>& should_stop) {
  return InRequestFields(Rebuild(context, request, should_stop), {{"coordinates", "clip"}});
}

}  // namespace motiondb::server
