#include "core/ops/planar_blend.h"

#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

absl::Status CheckPlanePoints(absl::string_view field, const Eigen::Ref<const RowMatrixXd>& m,
                              Eigen::Index rows) {
  if (m.cols() != 2 || m.rows() != rows) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": ", m.rows(), " x ", m.cols(), " values, expected ", rows, " x 2"));
  }
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (const int c : {0, 1}) {
      if (!std::isfinite(m(i, c))) {
        return absl::InvalidArgumentError(absl::StrCat(field, "[", i, "].", c == 0 ? "x" : "y",
                                                       " = ", m(i, c), " is not a finite number"));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<PlanarBlend> BlendOnPlane(const Eigen::Ref<const RowMatrixXd>& poses,
                                         const Eigen::Ref<const RowMatrixXd>& plane,
                                         const Eigen::Ref<const RowMatrixXd>& points,
                                         const PlanarBlendOptions& options) {
  const int dims = static_cast<int>(poses.cols());
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("poses", poses, dims, 1, true));
  MOTIONDB_RETURN_IF_ERROR(CheckPlanePoints("plane", plane, poses.rows()));
  if (points.rows() < 1) return absl::InvalidArgumentError("points: the path has no points");
  MOTIONDB_RETURN_IF_ERROR(CheckPlanePoints("points", points, points.rows()));
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckBetween("epsilon", options.epsilon, 0.0,
                                                      std::numeric_limits<double>::max()));
  PlanarBlend blend;
  blend.weights.resize(points.rows(), poses.rows());
  const double root_epsilon = std::sqrt(options.epsilon);
  for (Eigen::Index k = 0; k < points.rows(); ++k) {
    // Eq. 4.2's 1 / sqrt(d^2 + epsilon), each divided by the smallest: the squares would
    // underflow at 1e-200 and overflow at 1e200, hypot does neither, and the ratios lie in
    // [0, 1]. On a pose's own point with epsilon 0 (or where every distance is infinite) the
    // smallest is no number to divide by; the limit is the nearest poses alike.
    auto row = blend.weights.row(k);
    for (Eigen::Index i = 0; i < poses.rows(); ++i) {
      const Eigen::RowVector2d d = points.row(k) - plane.row(i);
      row[i] = std::hypot(std::hypot(d[0], d[1]), root_epsilon);
    }
    const double nearest = row.minCoeff();
    if (nearest > 0.0 && std::isfinite(nearest)) {
      row = row.unaryExpr([nearest](double r) { return nearest / r; });
    } else {
      row = row.unaryExpr([nearest](double r) { return r == nearest ? 1.0 : 0.0; });
    }
    row /= row.sum();
  }
  blend.coordinates = blend.weights * poses;
  return blend;
}

}  // namespace motiondb
