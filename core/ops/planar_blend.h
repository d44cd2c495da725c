// M-way planar interpolation (thesis 4.2): M poses placed at points of a plane; a point (X, Y)
// of the plane weighs pose i by w_i = ((X - dx_i)^2 + (Y - dy_i)^2 + epsilon)^-1/2 (eq. 4.2),
// the weights are taken as shares of their sum, and the blended point is sum w_i P_i (eq. 4.3),
// which unprojects to a pose. A path of plane points gives a clip, one frame a point.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_PLANAR_BLEND_H_
#define MOTIONDB_CORE_OPS_PLANAR_BLEND_H_

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"

namespace motiondb {

struct PlanarBlendOptions {
  // eq. 4.2's small number, finite and >= 0. At a pose's own point the weights are
  // epsilon^-1/2 against the others' inverse distances; with 0 the pose is reproduced exactly.
  double epsilon = 1e-6;
};

struct PlanarBlend {
  RowMatrixXd weights;      // points x poses, each row summing to 1
  RowMatrixXd coordinates;  // points x dims: the blended points
};

// `poses`: M x dims coordinates (M >= 1); `plane`: M x 2, each pose's place; `points`: K x 2,
// the path (K >= 1). INVALID_ARGUMENT naming poses, plane, points or epsilon.
absl::StatusOr<PlanarBlend> BlendOnPlane(const Eigen::Ref<const RowMatrixXd>& poses,
                                         const Eigen::Ref<const RowMatrixXd>& plane,
                                         const Eigen::Ref<const RowMatrixXd>& points,
                                         const PlanarBlendOptions& options = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_PLANAR_BLEND_H_
