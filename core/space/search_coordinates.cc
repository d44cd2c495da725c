#include "core/space/search_coordinates.h"

#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<RowMatrixXf> SearchCoordinates(const MotionSpace& space, const Clip& clip,
                                              int dims) {
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd curve, space.ProjectClip(clip, dims));
  MOTIONDB_ASSIGN_OR_RETURN(const Eigen::VectorXd scales,
                            space.MetricScales(static_cast<int>(curve.cols())));
  return (curve.array().rowwise() * scales.transpose().array()).cast<float>().matrix();
}

}  // namespace motiondb
