// The synthetic library's rendering (testing/synthetic_corpus.h): a plan turned into frames,
// each action eased from the rest pose to its peak and back, over an idle sway that keeps rest
// frames from repeating. Part of GenerateSyntheticCorpus.
#ifndef MOTIONDB_TESTING_INTERNAL_SYNTHETIC_RENDER_H_
#define MOTIONDB_TESTING_INTERNAL_SYNTHETIC_RENDER_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "testing/internal/synthetic_plan.h"

namespace motiondb::testing::synthetic {

// The idle sway's seeded phases (radians): breathing, weight shift, head turn.
struct SwayPhases {
  double breath = 0.0;
  double shift = 0.0;
  double turn = 0.0;
};

// Draws the sway's phases: the library's first draws.
SwayPhases DrawSwayPhases(Random& random);

// Renders every clip of `layout` on `threads` threads (> 0), clips in layout order; the output
// does not depend on the thread count.
absl::StatusOr<std::vector<Clip>> RenderClips(const SwayPhases& sway, double fps,
                                              const std::vector<PlannedAction>& plans,
                                              const std::vector<ClipPlan>& layout, int threads);

}  // namespace motiondb::testing::synthetic

#endif  // MOTIONDB_TESTING_INTERNAL_SYNTHETIC_RENDER_H_
