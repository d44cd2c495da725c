// Frame numbers at a clip's own rate (what the API speaks: 0-based, inclusive, the way the user
// sees the file) and at a space's sample rate (what the projections and the search use).
//
// A space frame s is at s / rate seconds; its original frame is round(s * fps / rate), clamped
// to the clip. An original frame f maps to round(f * rate / fps), clamped to the projection.
#ifndef MOTIONDB_SERVER_FRAME_CONVERSION_H_
#define MOTIONDB_SERVER_FRAME_CONVERSION_H_

#include <cstdint>
#include <optional>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"

namespace motiondb::server {

class FrameConversion {
 public:
  // `fps` and `frame_count`: the clip's own; `rate`: the space's; `space_frames`: rows of the
  // clip's projection (at least 1).
  FrameConversion(double fps, int frame_count, double rate, int64_t space_frames)
      : fps_(fps), frame_count_(frame_count), rate_(rate), space_frames_(space_frames) {}

  int ToOriginal(int64_t space_frame) const;
  int64_t ToSpace(int original_frame) const;
  // An original range to the space frames it covers (at least one).
  std::pair<int64_t, int64_t> ToSpace(FrameRange range) const;
  // The space frames whose original frames lie inside `range`: first..last, with last = first - 1
  // when none does (the range falls between two space frames). A range of space frames a..b
  // reaches into `range` (ToOriginal(a) <= range.last and ToOriginal(b) >= range.first)
  // exactly when a <= last and b >= first: ToOriginal never decreases.
  std::pair<int64_t, int64_t> SpaceFramesWithin(FrameRange range) const;

 private:
  double fps_;
  int frame_count_;
  double rate_;
  int64_t space_frames_;
};

// A stored clip, whole or a range of its frames (at its own rate), as a request names it:
// unset bounds are the clip's ends.
struct ClipSelection {
  int64_t clip_id = 0;
  std::optional<int> first_frame;
  std::optional<int> last_frame;
};

// The selection's frames, checked against a clip of `frame_count` frames: INVALID_ARGUMENT
// naming `field` when a bound lies outside the clip or first > last.
absl::StatusOr<FrameRange> ResolveFrameRange(std::optional<int> first, std::optional<int> last,
                                             int frame_count, absl::string_view field);
inline absl::StatusOr<FrameRange> ResolveFrameRange(const ClipSelection& selection, int frame_count,
                                                    absl::string_view field) {
  return ResolveFrameRange(selection.first_frame, selection.last_frame, frame_count, field);
}

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_FRAME_CONVERSION_H_
