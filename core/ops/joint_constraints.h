// Clean-up after unprojection (thesis 5.7): joint limits, which keep an edit from
// hyper-extending a joint, and selective blending, which protects chosen joints from an edit
// and so breaks the correlations the space's components impose. Both act on pose rotations, the
// edited ones against the source's, after the edited curve has been unprojected.
//
// A limit bounds the angle by which a joint turns away from its reference orientation (the
// space's mean for it), given per joint or learned from the source motion itself (5.7: limits
// "automatically calculated from reference motions"); a rotation beyond it is brought back along
// its own arc.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_JOINT_CONSTRAINTS_H_
#define MOTIONDB_CORE_OPS_JOINT_CONSTRAINTS_H_

#include <map>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "core/motion/matrix.h"
#include "core/space/motion_space.h"

namespace motiondb {

struct JointConstraints {
  // Selective blending: per joint, the share of the edit it takes, in [0, 1] (0 freezes it as
  // in the source); joints not named take all of it.
  std::map<std::string, double> edit_weights{};
  // Per joint, the largest angle in radians, in [0, pi], it may turn from its reference.
  std::map<std::string, double> max_angles{};
  // Limits from the source: every joint not in max_angles at most (1 + margin) times the
  // largest angle from its reference that the source reaches; finite, >= 0. nullopt: off.
  std::optional<double> source_margin{};

  bool empty() const { return edit_weights.empty() && max_angles.empty() && !source_margin; }
};

// INVALID_ARGUMENT naming the field and joint (edit_weights[LeftArm], ...) for an unknown joint
// of the space's skeleton or a value out of range.
absl::Status ValidateJointConstraints(const MotionSpace& space,
                                      const JointConstraints& constraints);

// Applies the constraints to `edited` (frames x 4 * joints, pose rotations) given the `source`
// rotations it was edited from (same shape): blending first, then limits. INVALID_ARGUMENT as
// ValidateJointConstraints, or for shapes that differ.
absl::Status ApplyJointConstraints(const MotionSpace& space, const JointConstraints& constraints,
                                   const Eigen::Ref<const RowMatrixXd>& source,
                                   RowMatrixXd* edited);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_JOINT_CONSTRAINTS_H_
