// Perturbed copies of real clips, to grow a library of real capture to hours (issue 11's real-data
// scale benchmark): each copy plays 0.8-1.25x as fast and every joint rotation of every frame is
// turned by a small random angle, so that copies are near, not exact, duplicates, as repeated
// takes are.
//
// Not mirrored: the Bandai skeletons' rest frames are not mirror images of each other per side
// (the arms' lateral axis is Z, the legs' Y), so a mirror needs a retarget, not a swap of tracks.
#ifndef MOTIONDB_TESTING_PERTURBED_COPY_H_
#define MOTIONDB_TESTING_PERTURBED_COPY_H_

#include <random>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"

namespace motiondb::testing {

struct PerturbOptions {
  // The copy plays this many times as fast as the original, drawn uniformly ((0, 10]).
  double min_speed = 0.8;
  double max_speed = 1.25;
  // Each rotation is turned about a random axis by an angle whose root mean square is this.
  double noise_deg = 1.0;
};

// A copy of `clip` perturbed as `options` say, with draws from `rng`; the frames are kept and
// the frame time changed (resampling to a space rate then gives the copy its own timing).
absl::StatusOr<Clip> PerturbedCopy(const Clip& clip, const PerturbOptions& options,
                                   std::mt19937_64& rng);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_PERTURBED_COPY_H_
