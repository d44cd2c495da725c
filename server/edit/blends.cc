#include "server/edit/blends.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "server/edit/internal/request_fields.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"
#include "util/stop_poll.h"

namespace motiondb::server {
namespace {

constexpr int kMaxFramesPerSegment = 10000;
constexpr int kMaxBlendFrames = 1000000;

// Placements of `poses` mixed per frame with the rows of `weights`; CANCELLED once
// `should_stop` says stop (a path of a million frames takes a second).
absl::StatusOr<Placement> MixedPlacement(const std::vector<const EditPose*>& poses,
                                         const RowMatrixXd& weights,
                                         const std::function<bool()>& should_stop) {
  std::vector<PlacementFrame> sources;
  for (const EditPose* pose : poses) sources.push_back({&pose->placement, 0});
  Placement placement = EmptyPlacement(poses.front()->placement, static_cast<int>(weights.rows()));
  StopPoll stop(should_stop, kPlacementFramesPerStopPoll);
  for (Eigen::Index k = 0; k < weights.rows(); ++k) {
    if (stop.Done(static_cast<int64_t>(poses.size()))) return EditStopped();
    const std::vector<double> row(weights.row(k).data(), weights.row(k).data() + weights.cols());
    MixPlacementFrame(sources, row, &placement, static_cast<int>(k));
  }
  return placement;
}

// The frames of the path with `per_segment` frames from each point to the next; INVALID_ARGUMENT
// for a bad path or count.
absl::StatusOr<int64_t> PathFrames(const std::vector<Eigen::Vector2d>& path, int per_segment) {
  if (per_segment < 1 || per_segment > kMaxFramesPerSegment) {
    return absl::InvalidArgumentError(absl::StrCat("frames_per_segment = ", per_segment,
                                                   " is out of range; expected 1..",
                                                   kMaxFramesPerSegment));
  }
  if (path.empty()) return absl::InvalidArgumentError("path: the path has no points");
  for (size_t i = 0; i < path.size(); ++i) {
    for (const int c : {0, 1}) {
      if (!std::isfinite(path[i][c])) {
        return absl::InvalidArgumentError(absl::StrCat("path[", i, "].", c == 0 ? "x" : "y", " = ",
                                                       path[i][c], " is not a finite number"));
      }
    }
  }
  const int64_t frames = static_cast<int64_t>(path.size() - 1) * per_segment + 1;
  if (frames > kMaxBlendFrames) {
    return absl::InvalidArgumentError(
        absl::StrCat("path: ", frames, " frames, at most ", kMaxBlendFrames));
  }
  return frames;
}

// The `frames` points of the path (PathFrames's) with `per_segment` frames from each point to
// the next.
RowMatrixXd PathPoints(const std::vector<Eigen::Vector2d>& path, int per_segment, int64_t frames) {
  RowMatrixXd points(frames, 2);
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    for (int k = 0; k < per_segment; ++k) {
      const double s = static_cast<double>(k) / per_segment;
      points.row(i * per_segment + k) = ((1.0 - s) * path[i] + s * path[i + 1]).transpose();
    }
  }
  points.row(frames - 1) = path.back().transpose();
  return points;
}

absl::StatusOr<InterpolateOutcome> InterpolateInSpace(const EditContext& context,
                                                      const InterpolateRequest& request,
                                                      const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(context.registry, request.space));
  const MotionSpace& space = *snapshot->space;
  MOTIONDB_ASSIGN_OR_RETURN(const SourceShape like,
                            ShapeOf(context.database, *snapshot, request.from, "from"));
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<double> t, InterpolationParameters(request.options));
  // Both methods' poses, a frame per t, and a step (t, three numbers) per t.
  const int64_t steps = static_cast<int64_t>(t.size());
  MOTIONDB_RETURN_IF_ERROR(
      CheckEditAnswer(context, space, like,
                      {.space_frames = steps,
                       .results = 2,
                       .sources = 2,
                       .extra_bytes = steps * (4 * kNumberFieldBytes + kFieldFramingBytes)},
                      request.output, "ask for fewer steps (or t values)"));
  MOTIONDB_ASSIGN_OR_RETURN(const EditSource from, LoadSource(context.database, *snapshot,
                                                              request.from, "from", should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(const EditSource to,
                            LoadSource(context.database, *snapshot, request.to, "to", should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(const EditPose a, PoseOf(space, from));
  MOTIONDB_ASSIGN_OR_RETURN(const EditPose b, PoseOf(space, to));
  RowMatrixXd poses(2, space.dims()), rotations(2, a.rotations.cols());
  poses << a.coordinates, b.coordinates;
  rotations << a.rotations, b.rotations;
  InterpolateOutcome outcome;
  MOTIONDB_ASSIGN_OR_RETURN(outcome.comparison,
                            InterpolatePoses(space, poses, rotations, request.options));
  RowMatrixXd weights(outcome.comparison.t.size(), 2);
  for (size_t i = 0; i < outcome.comparison.t.size(); ++i) {
    weights.row(i) << 1.0 - outcome.comparison.t[i], outcome.comparison.t[i];
  }
  MOTIONDB_ASSIGN_OR_RETURN(const Placement placement,
                            MixedPlacement({&a, &b}, weights, should_stop));
  const bool slerp = request.method == InterpolationMethod::kSlerp;
  const EditedMotion chosen{slerp ? outcome.comparison.slerp : outcome.comparison.mc_lerp,
                            placement};
  const EditedMotion other{slerp ? outcome.comparison.mc_lerp : outcome.comparison.slerp,
                           placement};
  const std::string op = slerp ? "slerp" : "mc-lerp";
  MOTIONDB_ASSIGN_OR_RETURN(
      const EditResult alternative,
      FinishEdit(context, space, from, other, {op, request.space}, {}, should_stop));
  outcome.other_bvh = alternative.bvh;
  MOTIONDB_ASSIGN_OR_RETURN(outcome.result, FinishEdit(context, space, from, chosen,
                                                       {op, request.space, {from.range, to.range}},
                                                       request.output, should_stop));
  return outcome;
}

absl::StatusOr<BlendOutcome> BlendInSpace(const EditContext& context, const BlendRequest& request,
                                          const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(context.registry, request.space));
  const MotionSpace& space = *snapshot->space;
  if (request.poses.empty()) return absl::InvalidArgumentError("poses: no poses to blend");
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t frames,
                            PathFrames(request.path, request.frames_per_segment));
  MOTIONDB_ASSIGN_OR_RETURN(
      const SourceShape like,
      ShapeOf(context.database, *snapshot, request.poses.front().pose, "poses[0].pose"));
  // A frame a path point, and each frame's weights (a double a pose).
  const int64_t pose_count = static_cast<int64_t>(request.poses.size());
  MOTIONDB_RETURN_IF_ERROR(CheckEditAnswer(
      context, space, like,
      {.space_frames = frames,
       .sources = pose_count,
       .extra_bytes =
           frames * (pose_count * static_cast<int64_t>(sizeof(double)) + 2 * kFieldFramingBytes)},
      request.output, "ask for fewer frames: fewer path points or a lower frames_per_segment"));
  const RowMatrixXd path = PathPoints(request.path, request.frames_per_segment, frames);
  std::vector<EditSource> sources;
  std::vector<EditPose> poses;
  RowMatrixXd coordinates(request.poses.size(), space.dims()), plane(request.poses.size(), 2);
  Provenance provenance{"blend", request.space};
  for (size_t i = 0; i < request.poses.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(EditSource source,
                              LoadSource(context.database, *snapshot, request.poses[i].pose,
                                         absl::StrCat("poses[", i, "].pose"), should_stop));
    MOTIONDB_ASSIGN_OR_RETURN(EditPose pose, PoseOf(space, source));
    coordinates.row(i) = pose.coordinates.row(0);
    plane.row(i) << request.poses[i].x, request.poses[i].y;
    provenance.sources.push_back(source.range);
    sources.push_back(std::move(source));
    poses.push_back(std::move(pose));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const PlanarBlend blend,
                            BlendOnPlane(coordinates, plane, path, request.options));
  std::vector<const EditPose*> mixed;
  for (const EditPose& pose : poses) mixed.push_back(&pose);
  MOTIONDB_RETURN_IF_ERROR(CheckEditStop(should_stop));
  EditedMotion edited;
  MOTIONDB_ASSIGN_OR_RETURN(edited.placement, MixedPlacement(mixed, blend.weights, should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(edited.rotations, space.Reconstruct(blend.coordinates, should_stop));
  BlendOutcome outcome;
  outcome.weights = blend.weights;
  MOTIONDB_ASSIGN_OR_RETURN(
      outcome.result, FinishEdit(context, space, sources.front(), edited, std::move(provenance),
                                 request.output, should_stop));
  return outcome;
}

}  // namespace

absl::StatusOr<InterpolateOutcome> Interpolate(const EditContext& context,
                                               const InterpolateRequest& request,
                                               const std::function<bool()>& should_stop) {
  // The two poses reach the operator as the rows of one matrix.
  return InRequestFields(InterpolateInSpace(context, request, should_stop),
                         {{"poses", "from and to"}});
}

absl::StatusOr<BlendOutcome> Blend(const EditContext& context, const BlendRequest& request,
                                   const std::function<bool()>& should_stop) {
  // The poses' places reach the operator as its plane, the path (already checked, and spread
  // over frames_per_segment) as its points.
  return InRequestFields(BlendInSpace(context, request, should_stop),
                         {{"plane", "poses"}, {"points", "path"}});
}

}  // namespace motiondb::server
