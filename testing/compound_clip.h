// Compound motions for the several-point search's measurements (issue 12, thesis 7.2.3): two
// clips of one skeleton played one after the other with a held pose between them, "A, a pause,
// B", the way an actor performs two actions in one take.
#ifndef MOTIONDB_TESTING_COMPOUND_CLIP_H_
#define MOTIONDB_TESTING_COMPOUND_CLIP_H_

#include "absl/status/statusor.h"
#include "core/motion/clip.h"

namespace motiondb::testing {

struct CompoundOptions {
  // The first clip's last frame is held this long after it (seconds, rounded to frames; >= 0).
  double hold_s = 1.0;
  // Then every joint rotation is slerped, and every position channel moved linearly, from the
  // first clip's last pose to the second's first over this long (seconds, rounded; >= 0).
  double blend_s = 0.25;
};

struct CompoundClip {
  Clip clip;  // at the first clip's rate, on its skeleton
  // Where each source clip's own frames lie in `clip`.
  FrameRange first;
  FrameRange second;
};

// `first`'s frames, its last frame held for hold_s, the transition, then `second`'s frames with
// the root joint's translation shifted horizontally (X, Z; Y is up and kept) so that the
// pelvis (heading.h's FindPelvis) starts where it ended in `first`. `second` is resampled to
// `first`'s rate when their frame times differ. INVALID_ARGUMENT when the skeletons differ in
// joint count or in any joint's channels, when the root has no position channels, or when an
// option is negative or not finite.
absl::StatusOr<CompoundClip> ConcatenateWithHold(const Clip& first, const Clip& second,
                                                 const CompoundOptions& options);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_COMPOUND_CLIP_H_
