// Writes a clip, or a frame range of it, as BVH with the clip's original hierarchy, offsets and
// channel orders. Rotations are decomposed into each joint's own Euler order, continuous from
// frame to frame.
#ifndef MOTIONDB_CORE_BVH_BVH_WRITER_H_
#define MOTIONDB_CORE_BVH_BVH_WRITER_H_

#include <functional>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"

namespace motiondb {

// The BVH text of `range` (default: the whole clip). Fails if the range is outside the clip.
// `threads` decompose the rotations and write the numbers (0: one a core; a thread for every
// 128 frames at most); the text is the same for any count. 10 s at 120 fps of 31 joints take
// about 5 ms on one thread. `should_stop` is asked before each block of 4096 frames:
// CANCELLED once it says stop.
absl::StatusOr<std::string> WriteBvh(const Clip& clip,
                                     std::optional<FrameRange> range = std::nullopt,
                                     int threads = 1,
                                     const std::function<bool()>& should_stop = {});

// Writes to `path` atomically (a temporary file renamed into place).
absl::Status WriteBvhFile(const std::string& path, const Clip& clip,
                          std::optional<FrameRange> range = std::nullopt);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_BVH_BVH_WRITER_H_
