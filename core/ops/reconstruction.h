// Reconstruction from the first n dimensions and its representational error (thesis 3.3.4): a
// motion's curve truncated to n dimensions, unprojected (the dimensions beyond n at the training
// mean), and the joint-angle error against the motion's own pose rotations, per joint and
// overall, optionally for every n (the curve the thesis inspects with its slider).
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_RECONSTRUCTION_H_
#define MOTIONDB_CORE_OPS_RECONSTRUCTION_H_

#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/space/motion_space.h"

namespace motiondb {

struct ReconstructOptions {
  // Dimensions kept, 1..the space's; -1: all of them.
  int dims = -1;
  // Also measure the overall error for every n from 1 to the space's dimensions.
  bool error_curve = false;
};

// Joint-angle error in radians over the frames of one joint, or of every joint.
struct AngleError {
  double mean_rad = 0.0;
  double max_rad = 0.0;
};

struct Reconstruction {
  int dims = 0;
  RowMatrixXd coordinates;           // frames x dims: the curve kept
  RowMatrixXd rotations;             // frames x 4 * joints: the pose rotations rebuilt from it
  std::vector<AngleError> joints{};  // per joint of the space's skeleton
  AngleError overall;                // over every joint of every frame
  // With error_curve: the overall error for n = 1, 2, ..., the space's dimensions.
  std::vector<ReconstructionError> curve{};
};

// `coordinates` (frames x the space's dims) and `rotations` (frames x 4 * joints) describe the
// same poses, as SpaceMotion holds them. INVALID_ARGUMENT naming dims, or coordinates/rotations
// for shapes that do not fit the space or each other. `should_stop` is asked as each
// reconstruction goes (MotionSpace::Reconstruct): CANCELLED once it says stop.
absl::StatusOr<Reconstruction> Reconstruct(const MotionSpace& space,
                                           const Eigen::Ref<const RowMatrixXd>& coordinates,
                                           const Eigen::Ref<const RowMatrixXd>& rotations,
                                           const ReconstructOptions& options = {},
                                           const std::function<bool()>& should_stop = {});

// The angle between the rotations of two blocks of one shape (frames x 4 * joints), per joint
// and over all.
void AngleErrors(const Eigen::Ref<const RowMatrixXd>& a, const Eigen::Ref<const RowMatrixXd>& b,
                 std::vector<AngleError>* joints, AngleError* overall);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_RECONSTRUCTION_H_
