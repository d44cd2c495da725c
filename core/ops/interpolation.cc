#include "core/ops/interpolation.h"

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "core/ops/internal/quat_rows.h"
#include "core/space/pose_encoder.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using ops_internal::CheckBetween;

constexpr int kMaxSteps = 10000;

RowMatrixXd SlerpJoints(const Eigen::Ref<const RowMatrixXd>& rotations,
                        const std::vector<double>& t) {
  RowMatrixXd slerp(t.size(), rotations.cols());
  for (Eigen::Index j = 0; j < rotations.cols(); j += 4) {
    const Quat qa = ops_internal::QuatAt(rotations, 0, j);
    const Quat qb = ops_internal::QuatAt(rotations, 1, j);
    for (size_t i = 0; i < t.size(); ++i) {
      ops_internal::SetQuatAt(Slerp(qa, qb, t[i]), slerp, static_cast<Eigen::Index>(i), j);
    }
  }
  return slerp;
}

}  // namespace

absl::StatusOr<std::vector<double>> InterpolationParameters(const InterpolationOptions& options) {
  if (!options.t.empty()) {
    if (options.t.size() > kMaxSteps) {
      return ops_internal::OutOfRange("t", static_cast<double>(options.t.size()),
                                      absl::StrCat("at most ", kMaxSteps, " values"));
    }
    for (size_t i = 0; i < options.t.size(); ++i) {
      MOTIONDB_RETURN_IF_ERROR(CheckBetween(absl::StrCat("t[", i, "]"), options.t[i], 0.0, 1.0));
    }
    return options.t;
  }
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("steps", options.steps, 2, kMaxSteps));
  std::vector<double> t(options.steps);
  for (int i = 0; i < options.steps; ++i) t[i] = static_cast<double>(i) / (options.steps - 1);
  return t;
}

absl::StatusOr<Interpolation> InterpolatePoses(const MotionSpace& space,
                                               const Eigen::Ref<const RowMatrixXd>& poses,
                                               const Eigen::Ref<const RowMatrixXd>& rotations,
                                               const InterpolationOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("poses", poses, space.dims(), 2, true));
  if (poses.rows() != 2 || rotations.rows() != 2 ||
      rotations.cols() != 4 * space.skeleton().joint_count()) {
    return absl::InvalidArgumentError("poses: interpolation takes exactly two poses");
  }
  const int dims = options.dims == -1 ? space.dims() : options.dims;
  if (dims < 1 || dims > space.dims()) {
    return ops_internal::OutOfRange("dims", options.dims,
                                    absl::StrCat("1..", space.dims(), " (or -1 for all)"));
  }
  Interpolation result;
  MOTIONDB_ASSIGN_OR_RETURN(result.t, InterpolationParameters(options));
  const int n = static_cast<int>(result.t.size());
  result.mc_lerp_coordinates.resize(n, dims);
  for (int i = 0; i < n; ++i) {
    result.mc_lerp_coordinates.row(i) =
        (1.0 - result.t[i]) * poses.row(0).head(dims) + result.t[i] * poses.row(1).head(dims);
  }
  MOTIONDB_ASSIGN_OR_RETURN(result.mc_lerp, space.Reconstruct(result.mc_lerp_coordinates));
  result.slerp = SlerpJoints(rotations, result.t);

  // SLERP's poses projected, their yaw rate and root velocity (which shape no joint)
  // interpolated linearly.
  PoseRotations slerp_pose{result.slerp, Eigen::VectorXd(), RowMatrixXd()};
  if (space.data().pose.remove_heading) {
    MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd vectors, space.Unproject(poses));
    const Eigen::Index extra = 3 * space.skeleton().joint_count();  // the first non-joint number
    RowMatrixXd lerped(n, vectors.cols() - extra);
    for (int i = 0; i < n; ++i) {
      lerped.row(i) = (1.0 - result.t[i]) * vectors.row(0).tail(lerped.cols()) +
                      result.t[i] * vectors.row(1).tail(lerped.cols());
    }
    slerp_pose.yaw_rate = lerped.col(0);
    if (space.data().pose.root_velocity) slerp_pose.root_velocity = lerped.rightCols(2);
  }
  MOTIONDB_ASSIGN_OR_RETURN(result.slerp_coordinates,
                            space.Project(EncodePoses(slerp_pose, space.data().references)));
  AngleErrors(result.mc_lerp, result.slerp, nullptr, &result.overall);
  for (int i = 0; i < n; ++i) {
    AngleError step;
    AngleErrors(result.mc_lerp.row(i), result.slerp.row(i), nullptr, &step);
    result.difference.push_back(step);
    Eigen::RowVectorXd point = Eigen::RowVectorXd::Zero(space.dims());
    point.head(dims) = result.mc_lerp_coordinates.row(i);
    MOTIONDB_ASSIGN_OR_RETURN(const double distance,
                              space.Distance(result.slerp_coordinates.row(i), point));
    result.curve_distance.push_back(distance);
  }
  return result;
}

}  // namespace motiondb
