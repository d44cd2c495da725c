#include "server/edit/transitions.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "server/edit/internal/request_fields.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"
#include "util/stop_poll.h"

namespace motiondb::server {
namespace {

// Request field `field`'s seconds, more than 0 and at most `max_frames` frames at `rate`, to
// frames at `rate`, at least one.
absl::StatusOr<int> Frames(absl::string_view field, double seconds, double rate, int max_frames) {
  MOTIONDB_RETURN_IF_ERROR(CheckDuration(field, seconds, false, max_frames, rate));
  return std::max(1, static_cast<int>(std::lround(seconds * rate)));
}

// The first range, `gap` and the second range in a row, with the placement of the gap mixed
// linearly between the ranges' ends; CANCELLED once `should_stop` says stop.
absl::StatusOr<EditedMotion> Joined(const MotionSpace& space, const EditSource& first,
                                    const EditSource& second, const RowMatrixXd& gap,
                                    const std::function<bool()>& should_stop) {
  const SpaceMotion& a = first.motion;
  const SpaceMotion& b = second.motion;
  const int na = static_cast<int>(a.coordinates.rows());
  const int nb = static_cast<int>(b.coordinates.rows());
  const int ng = static_cast<int>(gap.rows());
  RowMatrixXd curve(na + ng + nb, a.coordinates.cols());
  curve << a.coordinates, gap, b.coordinates;
  EditedMotion joined{RowMatrixXd(), EmptyPlacement(a.placement, na + ng + nb)};
  StopPoll stop(should_stop, kPlacementFramesPerStopPoll);
  for (int f = 0; f < na; ++f) {
    if (stop.Done(1)) return EditStopped();
    MixPlacementFrame({{&a.placement, f}}, {1.0}, &joined.placement, f);
  }
  for (int k = 0; k < ng; ++k) {
    if (stop.Done(2)) return EditStopped();
    const double t = static_cast<double>(k + 1) / (ng + 1);
    MixPlacementFrame({{&a.placement, na - 1}, {&b.placement, 0}}, {1.0 - t, t}, &joined.placement,
                      na + k);
  }
  for (int f = 0; f < nb; ++f) {
    if (stop.Done(1)) return EditStopped();
    MixPlacementFrame({{&b.placement, f}}, {1.0}, &joined.placement, na + ng + f);
  }
  MOTIONDB_ASSIGN_OR_RETURN(joined.rotations, space.Reconstruct(curve, should_stop));
  return joined;
}

absl::StatusOr<FillGapOutcome> Gap(const EditContext& context, const MotionSpace& space,
                                   const FillGapRequest& request, const EditSource& first,
                                   const EditSource& second,
                                   const std::function<bool()>& should_stop) {
  GapFillOptions options = request.gap;
  MOTIONDB_ASSIGN_OR_RETURN(options.frames,
                            Frames("gap_s", request.gap_s, space.sample_rate(), kMaxGapFrames));
  GapFillOptions linear = options;
  linear.method = GapMethod::kLinear;
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd gap,
                            FillGap(first.motion.coordinates, second.motion.coordinates, options));
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd line,
                            FillGap(first.motion.coordinates, second.motion.coordinates, linear));
  MOTIONDB_ASSIGN_OR_RETURN(const EditedMotion joined,
                            Joined(space, first, second, gap, should_stop));
  // The linear fill's rotations, for its seams: they differ from `joined`'s only in the gap, and
  // reconstruction goes frame by frame, so only the gap is reconstructed (the whole joined
  // motion again took about a tenth of the call).
  const int na = static_cast<int>(first.motion.coordinates.rows());
  RowMatrixXd linear_rotations = joined.rotations;
  MOTIONDB_ASSIGN_OR_RETURN(linear_rotations.middleRows(na, line.rows()),
                            space.Reconstruct(line, should_stop));
  FillGapOutcome outcome;
  outcome.transition_frames = options.frames;
  for (const int seam : {na - 1, na + options.frames}) {
    outcome.seams.push_back({VelocityJump(joined.rotations, seam, space.sample_rate()),
                             VelocityJump(linear_rotations, seam, space.sample_rate())});
  }
  MOTIONDB_ASSIGN_OR_RETURN(outcome.result,
                            FinishEdit(context, space, first, joined,
                                       {"fill-gap", request.space, {first.range, second.range}},
                                       request.output, should_stop));
  return outcome;
}

absl::StatusOr<FillGapOutcome> Overlap(const EditContext& context, const MotionSpace& space,
                                       const FillGapRequest& request, const EditSource& first,
                                       const EditSource& second,
                                       const std::function<bool()>& should_stop) {
  AlignedBlendOptions options = request.blend;
  MOTIONDB_ASSIGN_OR_RETURN(options.overlap_frames, Frames("overlap_s", request.overlap_s,
                                                           space.sample_rate(), kMaxOverlapFrames));
  const SpaceMotion& a = first.motion;
  const SpaceMotion& b = second.motion;
  // Told here in seconds; the operator would say it in frames.
  if (options.overlap_frames > a.coordinates.rows()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "overlap_s = ", request.overlap_s, " is out of range; expected at most the first range's ",
        a.coordinates.rows() / space.sample_rate(), " seconds (", a.coordinates.rows(),
        " frames at the space's ", space.sample_rate(), " fps)"));
  }
  // The overlap is the warp's query: its table grows with the square of the overlap and of the
  // slope limit, and is held to a search query's at most (server/search_runner.cc).
  if (options.align) {
    const int64_t budget = AnchoredWarpTableBytes(context.max_query_frames, kDefaultSlopeLimit);
    if (AnchoredWarpTableBytes(options.overlap_frames, options.warp.slope_limit) > budget) {
      return absl::InvalidArgumentError(absl::StrCat(
          "overlap_s = ", request.overlap_s, ": an aligned overlap of ", options.overlap_frames,
          " frames at the space's ", space.sample_rate(), " fps at slope limit ",
          options.warp.slope_limit, " takes more memory than the longest search query (",
          context.max_query_frames, " frames at slope limit ", kDefaultSlopeLimit,
          ", --max-query-frames); shorten the overlap or lower slope_limit"));
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(const AlignedBlend plan,
                            PlanAlignedBlend(a.coordinates, b.coordinates, options, should_stop));
  EditedMotion blended{RowMatrixXd(),
                       EmptyPlacement(a.placement, static_cast<int>(plan.frames.size()))};
  StopPoll stop(should_stop, kPlacementFramesPerStopPoll);
  for (size_t k = 0; k < plan.frames.size(); ++k) {
    if (stop.Done(2)) return EditStopped();
    const BlendFrame& frame = plan.frames[k];
    std::vector<PlacementFrame> sources;
    std::vector<double> weights;
    if (frame.a >= 0) {
      sources.push_back({&a.placement, frame.a});
      weights.push_back(1.0 - frame.weight_b);
    }
    if (frame.b >= 0) {
      sources.push_back({&b.placement, frame.b});
      weights.push_back(frame.weight_b);
    }
    MixPlacementFrame(sources, weights, &blended.placement, static_cast<int>(k));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      blended.rotations,
      space.Reconstruct(MixCurves(plan.frames, a.coordinates, b.coordinates), should_stop));
  FillGapOutcome outcome;
  outcome.transition_frames = options.overlap_frames;
  outcome.warp_score = plan.warp_score;
  MOTIONDB_ASSIGN_OR_RETURN(
      outcome.result, FinishEdit(context, space, first, blended,
                                 {"blend-overlap", request.space, {first.range, second.range}},
                                 request.output, should_stop));
  return outcome;
}

// The answer's size checked before the ranges are read: both ranges and the gap between them
// (an overlap makes fewer frames than the ranges), exported like the first.
absl::Status CheckTransitionAnswer(const EditContext& context, const SpaceSnapshot& snapshot,
                                   const FillGapRequest& request) {
  const MotionSpace& space = *snapshot.space;
  MOTIONDB_ASSIGN_OR_RETURN(const SourceShape first,
                            ShapeOf(context.database, snapshot, request.first, "first"));
  MOTIONDB_ASSIGN_OR_RETURN(const SourceShape second,
                            ShapeOf(context.database, snapshot, request.second, "second"));
  int64_t gap = 0;
  if (std::isfinite(request.overlap_s) && request.overlap_s == 0.0) {
    MOTIONDB_ASSIGN_OR_RETURN(gap,
                              Frames("gap_s", request.gap_s, space.sample_rate(), kMaxGapFrames));
  }
  return CheckEditAnswer(
      context, space, first,
      {.space_frames = first.space_frames + gap + second.space_frames, .sources = 2},
      request.output, "ask for shorter ranges (first, second) or a shorter gap_s");
}

absl::StatusOr<FillGapOutcome> Transition(const EditContext& context, const FillGapRequest& request,
                                          const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(context.registry, request.space));
  MOTIONDB_RETURN_IF_ERROR(CheckTransitionAnswer(context, *snapshot, request));
  MOTIONDB_ASSIGN_OR_RETURN(
      const EditSource first,
      LoadSource(context.database, *snapshot, request.first, "first", should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(
      const EditSource second,
      LoadSource(context.database, *snapshot, request.second, "second", should_stop));
  if (!std::isfinite(request.overlap_s) || request.overlap_s != 0.0) {
    return Overlap(context, *snapshot->space, request, first, second, should_stop);
  }
  return Gap(context, *snapshot->space, request, first, second, should_stop);
}

}  // namespace

absl::StatusOr<FillGapOutcome> FillGap(const EditContext& context, const FillGapRequest& request,
                                       const std::function<bool()>& should_stop) {
  // The request's ranges reach the operators as curves a and b (before and after), its warp
  // fields as the warp's options; its seconds are checked before they become frames.
  return InRequestFields(Transition(context, request, should_stop),
                         {{"a", "first"},
                          {"before", "first"},
                          {"b", "second"},
                          {"after", "second"},
                          {"warp.slope_limit", "slope_limit"},
                          {"warp.dims", "warp_dims"}});
}

}  // namespace motiondb::server
