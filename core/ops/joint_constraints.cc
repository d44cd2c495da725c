#include "core/ops/joint_constraints.h"

#include <algorithm>
#include <limits>
#include <numbers>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "core/ops/internal/quat_rows.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using ops_internal::QuatAt;
using ops_internal::SetQuatAt;

absl::Status CheckJointValues(const Skeleton& skeleton, absl::string_view field,
                              const std::map<std::string, double>& values, double high) {
  for (const auto& [joint, value] : values) {
    const std::string name = absl::StrCat(field, "[", joint, "]");
    if (skeleton.FindJoint(joint) < 0) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": the skeleton has no such joint"));
    }
    MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckBetween(name, value, 0.0, high));
  }
  return absl::OkStatus();
}

Quat Reference(const MotionSpace& space, int joint) {
  const auto r = space.data().references.row(joint);
  return Quat(r[0], r[1], r[2], r[3]);
}

// Each joint's limit: given, learned from the source, or none (infinity).
std::vector<double> Limits(const MotionSpace& space, const JointConstraints& constraints,
                           const Eigen::Ref<const RowMatrixXd>& source) {
  const Skeleton& skeleton = space.skeleton();
  std::vector<double> limits(skeleton.joint_count(), std::numeric_limits<double>::infinity());
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const auto given = constraints.max_angles.find(skeleton.joint(j).name);
    if (given != constraints.max_angles.end()) {
      limits[j] = given->second;
    } else if (constraints.source_margin) {
      double reach = 0.0;
      for (Eigen::Index f = 0; f < source.rows(); ++f) {
        reach = std::max(reach, AngleBetween(QuatAt(source, f, 4 * j), Reference(space, j)));
      }
      limits[j] = (1.0 + *constraints.source_margin) * reach;
    }
  }
  return limits;
}

}  // namespace

absl::Status ValidateJointConstraints(const MotionSpace& space,
                                      const JointConstraints& constraints) {
  const Skeleton& skeleton = space.skeleton();
  MOTIONDB_RETURN_IF_ERROR(
      CheckJointValues(skeleton, "edit_weights", constraints.edit_weights, 1.0));
  MOTIONDB_RETURN_IF_ERROR(
      CheckJointValues(skeleton, "max_angles", constraints.max_angles, std::numbers::pi));
  if (constraints.source_margin) {
    MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckBetween("source_margin", *constraints.source_margin,
                                                        0.0, std::numeric_limits<double>::max()));
  }
  return absl::OkStatus();
}

absl::Status ApplyJointConstraints(const MotionSpace& space, const JointConstraints& constraints,
                                   const Eigen::Ref<const RowMatrixXd>& source,
                                   RowMatrixXd* edited) {
  MOTIONDB_RETURN_IF_ERROR(ValidateJointConstraints(space, constraints));
  const int joints = space.skeleton().joint_count();
  if (source.rows() != edited->rows() || source.cols() != 4 * joints ||
      edited->cols() != 4 * joints) {
    return absl::InvalidArgumentError(
        absl::StrCat("rotations: the source is ", source.rows(), " x ", source.cols(),
                     " and the edit ", edited->rows(), " x ", edited->cols(),
                     "; expected one shape with ", 4 * joints, " columns"));
  }
  for (const auto& [joint, weight] : constraints.edit_weights) {
    const int j = space.skeleton().FindJoint(joint);
    for (Eigen::Index f = 0; f < edited->rows(); ++f) {
      SetQuatAt(Slerp(QuatAt(source, f, 4 * j), QuatAt(*edited, f, 4 * j), weight), *edited, f,
                4 * j);
    }
  }
  const std::vector<double> limits = Limits(space, constraints, source);
  for (int j = 0; j < joints; ++j) {
    if (!std::isfinite(limits[j])) continue;
    const Quat reference = Reference(space, j);
    for (Eigen::Index f = 0; f < edited->rows(); ++f) {
      const Quat q = QuatAt(*edited, f, 4 * j);
      const double angle = AngleBetween(q, reference);
      if (angle > limits[j]) SetQuatAt(Slerp(reference, q, limits[j] / angle), *edited, f, 4 * j);
    }
  }
  return absl::OkStatus();
}

}  // namespace motiondb
