#include "testing/perturbed_copy.h"

#include <cmath>

#include "core/motion/rotation.h"

namespace motiondb::testing {

absl::StatusOr<Clip> PerturbedCopy(const Clip& clip, const PerturbOptions& options,
                                   std::mt19937_64& rng) {
  if (!(options.min_speed > 0 && options.min_speed <= options.max_speed &&
        options.max_speed <= 10) ||
      !(options.noise_deg >= 0)) {
    return absl::InvalidArgumentError("PerturbOptions: speeds in (0, 10], min <= max, noise >= 0");
  }
  const double speed =
      std::uniform_real_distribution<double>(options.min_speed, options.max_speed)(rng);
  // Three independent components of this deviation make a turn of noise_deg in root mean square.
  std::normal_distribution<double> component(0.0,
                                             options.noise_deg * M_PI / 180.0 / std::sqrt(3.0));
  RowMatrixXd rotations = clip.rotations();
  const int joints = static_cast<int>(rotations.cols() / 4);
  for (Eigen::Index f = 0; f < rotations.rows(); ++f) {
    for (int j = 0; j < joints; ++j) {
      const Quat turned = clip.rotation(static_cast<int>(f), j) *
                          ExpMap(Eigen::Vector3d(component(rng), component(rng), component(rng)));
      rotations.row(f).segment<4>(4 * j) << turned.w(), turned.x(), turned.y(), turned.z();
    }
  }
  return Clip::Create(clip.shared_skeleton(), clip.frame_time() / speed, std::move(rotations),
                      clip.positions());
}

}  // namespace motiondb::testing
