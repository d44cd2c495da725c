// Resampling a clip to another frame rate: slerp for rotations (shorter arc), lerp for positions.
#ifndef MOTIONDB_CORE_MOTION_RESAMPLE_H_
#define MOTIONDB_CORE_MOTION_RESAMPLE_H_

#include <cstdint>
#include <functional>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"

namespace motiondb {

// The fastest rate Resample() makes, frames per second.
inline constexpr double kMaxResampleRate = 10000.0;

// Samples `clip` at t = k / target_fps for every k with t within the clip's span
// [0, (frame_count - 1) * frame_time], allowing 1% of an output frame past the end (taken as
// the last frame) so that rounded frame times such as 0.0333333 keep every frame. `target_fps` must
// be finite and in (0, kMaxResampleRate]. `threads` share the output frames (0: one a core; a
// thread for every 256 frames at most); the result is the same for any count. `should_stop`
// is asked about every millisecond of work on each thread: CANCELLED once it says stop.
absl::StatusOr<Clip> Resample(const Clip& clip, double target_fps, int threads = 1,
                              const std::function<bool()>& should_stop = {});

// The number of frames Resample() makes of `frame_count` frames `frame_time` apart (without its
// limit on the output's size). `target_fps` must be in Resample's range.
int64_t ResampledFrameCount(int frame_count, double frame_time, double target_fps);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_RESAMPLE_H_
