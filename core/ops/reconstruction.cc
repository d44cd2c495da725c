#include "core/ops/reconstruction.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "core/ops/internal/quat_rows.h"
#include "util/status_macros.h"

namespace motiondb {

void AngleErrors(const Eigen::Ref<const RowMatrixXd>& a, const Eigen::Ref<const RowMatrixXd>& b,
                 std::vector<AngleError>* joints, AngleError* overall) {
  const Eigen::Index count = a.cols() / 4;
  std::vector<AngleError> per_joint(count);
  *overall = {};
  for (Eigen::Index f = 0; f < a.rows(); ++f) {
    for (Eigen::Index j = 0; j < count; ++j) {
      const double angle =
          AngleBetween(ops_internal::QuatAt(a, f, 4 * j), ops_internal::QuatAt(b, f, 4 * j));
      per_joint[j].mean_rad += angle;
      per_joint[j].max_rad = std::max(per_joint[j].max_rad, angle);
    }
  }
  for (AngleError& joint : per_joint) {
    overall->mean_rad += joint.mean_rad;
    overall->max_rad = std::max(overall->max_rad, joint.max_rad);
    if (a.rows() > 0) joint.mean_rad /= static_cast<double>(a.rows());
  }
  if (a.size() > 0) overall->mean_rad /= static_cast<double>(a.rows() * count);
  if (joints != nullptr) *joints = std::move(per_joint);
}

absl::StatusOr<Reconstruction> Reconstruct(const MotionSpace& space,
                                           const Eigen::Ref<const RowMatrixXd>& coordinates,
                                           const Eigen::Ref<const RowMatrixXd>& rotations,
                                           const ReconstructOptions& options,
                                           const std::function<bool()>& should_stop) {
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckPoints("coordinates", coordinates, space.dims(), 1, /*exact=*/true));
  const int joints = space.skeleton().joint_count();
  if (rotations.rows() != coordinates.rows() || rotations.cols() != 4 * joints) {
    return absl::InvalidArgumentError(absl::StrCat("rotations are ", rotations.rows(), " x ",
                                                   rotations.cols(), ", expected ",
                                                   coordinates.rows(), " x ", 4 * joints));
  }
  Reconstruction result;
  result.dims = options.dims == -1 ? space.dims() : options.dims;
  if (result.dims < 1 || result.dims > space.dims()) {
    return ops_internal::OutOfRange("dims", options.dims,
                                    absl::StrCat("1..", space.dims(), " (or -1 for all)"));
  }
  result.coordinates = coordinates.leftCols(result.dims);
  MOTIONDB_ASSIGN_OR_RETURN(result.rotations, space.Reconstruct(result.coordinates, should_stop));
  AngleErrors(rotations, result.rotations, &result.joints, &result.overall);
  if (options.error_curve) {
    for (int n = 1; n <= space.dims(); ++n) {
      MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd rebuilt,
                                space.Reconstruct(coordinates.leftCols(n), should_stop));
      AngleError error;
      AngleErrors(rotations, rebuilt, nullptr, &error);
      result.curve.push_back({n, error.mean_rad, error.max_rad});
    }
  }
  return result;
}

}  // namespace motiondb
