// EditService's transitions between two stored clip ranges (thesis 4.3, 7.2.3): a gap filled by
// Hermite interpolation in the space (against the linear baseline, both measured by the jump in
// joint velocity at the two seams), or an overlap blended after time-warping the second range
// onto the first.
#ifndef MOTIONDB_SERVER_EDIT_TRANSITIONS_H_
#define MOTIONDB_SERVER_EDIT_TRANSITIONS_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/ops/aligned_blend.h"
#include "core/ops/gap_fill.h"
#include "server/edit/context.h"

namespace motiondb::server {

struct FillGapRequest {
  std::string space;
  ClipSelection first;
  ClipSelection second;
  // The gap between the first range's last frame and the second's first, seconds more than 0
  // and at most kMaxGapFrames frames at the space rate (3333.33 s at 30 fps); at least one frame.
  // Used when overlap_s is 0.
  double gap_s = 0.5;
  GapFillOptions gap{};  // its frames come from gap_s
  // Seconds by which the second range overlaps the first's end, at most the first range and
  // kMaxOverlapFrames frames at the space rate; > 0 blends them (time-aligned unless
  // blend.align is false) instead of filling a gap.
  double overlap_s = 0.0;
  AlignedBlendOptions blend{};  // its overlap_frames come from overlap_s
  EditOutput output{};
};

// The joint-velocity jump at a seam (rad/s), for the method used and for the linear baseline.
struct SeamJump {
  AngleError chosen;
  AngleError linear;
};

struct FillGapOutcome {
  EditResult result;
  int transition_frames = 0;      // gap or overlap frames, at the space rate
  std::vector<SeamJump> seams{};  // a gap's two: the first range's end, the second's start
  double warp_score = 0.0;        // an overlap's: mean distance of the matched frames
};

// NOT_FOUND for an unknown space or clip; INVALID_ARGUMENT naming the request's field (first,
// second, gap_s, overlap_s, damping, slope_limit, warp_dims, ...); nothing is stored on error.
absl::StatusOr<FillGapOutcome> FillGap(const EditContext& context, const FillGapRequest& request,
                                       const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_TRANSITIONS_H_
