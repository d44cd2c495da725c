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
  if (!m.allFinite()) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": NaN or infinite coordinates"));
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
  for (Eigen::Index k = 0; k < points.rows(); ++k) {
    for (Eigen::Index i = 0; i < poses.rows(); ++i) {
      const double squared = (points.row(k) - plane.row(i)).squaredNorm() + options.epsilon;
      // On a pose's own point with epsilon 0 the weight is infinite: the limit is that pose.
      blend.weights(k, i) =
          squared > 0.0 ? 1.0 / std::sqrt(squared) : std::numeric_limits<double>::infinity();
    }
    auto row = blend.weights.row(k);
    if (!row.allFinite()) {
      row = row.unaryExpr([](double w) { return std::isinf(w) ? 1.0 : 0.0; });
    }
    row /= row.sum();
  }
  blend.coordinates = blend.weights * poses;
  return blend;
}

}  // namespace motiondb
