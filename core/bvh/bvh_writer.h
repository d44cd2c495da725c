// Writes a clip, or a frame range of it, as BVH with the clip's original hierarchy, offsets and
// channel orders. Rotations are decomposed into each joint's own Euler order, continuous from
// frame to frame.
#ifndef MOTIONDB_CORE_BVH_BVH_WRITER_H_
#define MOTIONDB_CORE_BVH_BVH_WRITER_H_

#include <cstdint>
#include <functional>
#include <memory>
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

// BVH text written piece by piece, for a clip too long to hold as one text (a streamed export):
// the header once, then the rows of the clip's frames in batches, in order. The pieces joined are
// WriteBvh's text of those frames, however they were batched.
class BvhStreamWriter {
 public:
  // For clips of `skeleton` (their own offsets and channels); `threads` as WriteBvh takes them.
  explicit BvhStreamWriter(std::shared_ptr<const Skeleton> skeleton, int threads = 1);
  ~BvhStreamWriter();
  BvhStreamWriter(const BvhStreamWriter&) = delete;
  BvhStreamWriter& operator=(const BvhStreamWriter&) = delete;

  // The hierarchy and the MOTION header of `frames` frames `frame_time` seconds apart.
  std::string Header(int64_t frames, double frame_time) const;
  // Appends to `out` the rows of `batch`'s `frames` (default: all), the frames that follow those
  // appended before (their Euler angles continue from them). INVALID_ARGUMENT for a batch of
  // another skeleton (joints or channels), or a range outside it; CANCELLED once `should_stop`,
  // asked before each block of 4096 frames, says stop.
  absl::Status AppendRows(const Clip& batch, std::optional<FrameRange> frames, std::string& out,
                          const std::function<bool()>& should_stop = {});

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// At least the length of a MOTION row of a clip of `skeleton`: every value at its longest.
int64_t BvhRowBound(const Skeleton& skeleton);
// At least the length of WriteBvh's text of `frames` frames of a clip of `skeleton` (at any
// frame time): the hierarchy exactly, every value at its longest. What an answer holding it is
// checked against before it is written.
int64_t BvhTextBound(const Skeleton& skeleton, int64_t frames);

// Writes to `path` atomically (a temporary file renamed into place).
absl::Status WriteBvhFile(const std::string& path, const Clip& clip,
                          std::optional<FrameRange> range = std::nullopt);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_BVH_BVH_WRITER_H_
