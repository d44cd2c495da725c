// Resampling a clip to another frame rate: slerp for rotations (shorter arc), lerp for positions.
#ifndef MOTIONDB_CORE_RESAMPLE_H_
#define MOTIONDB_CORE_RESAMPLE_H_

#include "absl/status/statusor.h"
#include "core/clip.h"

namespace motiondb {

// Samples `clip` at t = k / target_fps for every k with t within the clip's span
// [0, (frame_count - 1) * frame_time]. The first sample is frame 0; the last is at or before
// the last frame. `target_fps` must be finite and in (0, 10000].
absl::StatusOr<Clip> Resample(const Clip& clip, double target_fps);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_RESAMPLE_H_
