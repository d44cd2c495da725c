// A time-aligned blend of two overlapping clips (thesis 4.1's overlapping case, improved as
// 7.2.3 suggests: "the time warping code ... is also useful for improving the quality of
// arbitrary interpolations"). The end of the first clip and the start of the second overlap by
// some frames; the second is first time-warped onto the first with the search's slope-limited
// warp (core/search/warp), anchored at the overlap's first frames, so that the blend mixes
// matching phases of the two motions rather than whatever frames coincide; then a linear ramp
// hands over from the first to the second across the overlap, and the second plays on from the
// frame the warp reached.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_ALIGNED_BLEND_H_
#define MOTIONDB_CORE_OPS_ALIGNED_BLEND_H_

#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/search/warp/time_warp.h"

namespace motiondb {

// The longest overlap AlignedBlendOptions::overlap_frames may ask for.
inline constexpr int kMaxOverlapFrames = 100000;

struct AlignedBlendOptions {
  // Frames of the first clip's end that blend into the second's start, 1..kMaxOverlapFrames and
  // at most the first clip's length.
  int overlap_frames = 15;
  // Warp the second clip onto the first before blending; false blends frame for frame.
  bool align = true;
  // The warp's model (core/search/warp/time_warp.h): the second clip advances 0..slope_limit
  // frames per frame of the first; its distance is Euclidean over the first `dims` coordinates.
  WarpConstraints warp = {};
};

// One output frame: frame `a` of the first clip and frame `b` of the second mixed with weight
// `weight_b` on the second; -1 for a clip that takes no part.
struct BlendFrame {
  int a = -1;
  int b = -1;
  double weight_b = 0.0;
};

struct AlignedBlend {
  std::vector<BlendFrame> frames{};  // the first clip up to the overlap, the overlap, the rest
  double warp_score = 0.0;           // the warp's mean distance over the overlap (unwarped too)
};

// `a` and `b`: frames x dims at one rate. INVALID_ARGUMENT naming overlap_frames, warp.dims,
// warp.slope_limit, a or b, or saying the second clip is too short for the overlap. The warp's
// memory grows with the square of the overlap (AnchoredWarpTableBytes): callers bound it.
// `should_stop` is asked as the warp goes: CANCELLED once it says stop.
absl::StatusOr<AlignedBlend> PlanAlignedBlend(const Eigen::Ref<const RowMatrixXd>& a,
                                              const Eigen::Ref<const RowMatrixXd>& b,
                                              const AlignedBlendOptions& options = {},
                                              const std::function<bool()>& should_stop = {});

// The plan's frames of two curves (frames x dims each).
RowMatrixXd MixCurves(const std::vector<BlendFrame>& frames, const Eigen::Ref<const RowMatrixXd>& a,
                      const Eigen::Ref<const RowMatrixXd>& b);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_ALIGNED_BLEND_H_
