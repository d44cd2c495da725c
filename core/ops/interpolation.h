// Two-pose interpolation (thesis 4.1): MC-LERP, a straight line in the space between the two
// poses' points, unprojected; and per-joint SLERP of their rotations, the usual method, side by
// side, with the difference between them measured two ways: the joint angles between the two
// poses at each t, and how far the SLERP pose's projection lies from the MC-LERP point (the
// thesis compares the two curves, fig. 4.2). With all dimensions, MC-LERP is Grassia's
// log-quaternion interpolation about each joint's mean orientation.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_INTERPOLATION_H_
#define MOTIONDB_CORE_OPS_INTERPOLATION_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/ops/reconstruction.h"
#include "core/space/motion_space.h"

namespace motiondb {

struct InterpolationOptions {
  // The parameters to sample, each in [0, 1]; empty: `steps` evenly spaced from 0 to 1.
  std::vector<double> t{};
  // Samples when `t` is empty, 2..10000; 11 gives t = 0, 0.1, ..., 1.
  int steps = 11;
  // Dimensions MC-LERP interpolates, 1..the space's (those beyond stay at the training mean,
  // so that a joint they carry holds still, as 4.1 warns); -1: all.
  int dims = -1;
};

struct Interpolation {
  std::vector<double> t{};
  RowMatrixXd mc_lerp_coordinates;  // t.size() x dims
  RowMatrixXd mc_lerp;              // t.size() x 4 * joints: pose rotations
  RowMatrixXd slerp;                // t.size() x 4 * joints: pose rotations
  RowMatrixXd slerp_coordinates;    // t.size() x the space's dims: SLERP's poses projected
  // Per t: the joint angles between the MC-LERP and SLERP poses.
  std::vector<AngleError> difference{};
  AngleError overall;  // over every t and joint
  // Per t: the space's distance (all dimensions) from the SLERP pose's projection to the
  // MC-LERP point.
  std::vector<double> curve_distance{};
};

// The parameters InterpolatePoses samples: options.t, or options.steps from 0 to 1.
// INVALID_ARGUMENT naming t, t[i] or steps.
absl::StatusOr<std::vector<double>> InterpolationParameters(const InterpolationOptions& options);

// `poses`: 2 x the space's dims, the two poses' coordinates; `rotations`: 2 x 4 * joints, the
// pose rotations they encode (SpaceMotion rows). INVALID_ARGUMENT naming t[i], steps, dims or
// the inputs.
absl::StatusOr<Interpolation> InterpolatePoses(const MotionSpace& space,
                                               const Eigen::Ref<const RowMatrixXd>& poses,
                                               const Eigen::Ref<const RowMatrixXd>& rotations,
                                               const InterpolationOptions& options = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_INTERPOLATION_H_
