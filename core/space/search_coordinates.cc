#include "core/space/search_coordinates.h"

#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<RowMatrixXf> SearchCoordinates(const MotionSpace& space, const Clip& clip, int dims,
                                              const HumanoidMap* map) {
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd poses, space.EncodeClip(clip, map));
  return SearchCoordinatesOfPoses(space, poses, dims);
}

absl::StatusOr<RowMatrixXf> SearchCoordinatesOfPoses(const MotionSpace& space,
                                                     const Eigen::Ref<const RowMatrixXd>& poses,
                                                     int dims) {
  const RowMatrixXd& transform = space.data().search_transform;
  // A learned metric mixes every dimension into each of its own: all are projected then.
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd curve,
                            space.Project(poses, transform.size() > 0 ? -1 : dims));
  MOTIONDB_ASSIGN_OR_RETURN(const Eigen::VectorXd scales,
                            space.MetricScales(static_cast<int>(curve.cols())));
  const RowMatrixXd scaled = curve.array().rowwise() * scales.transpose().array();
  if (transform.size() == 0) return scaled.cast<float>();
  MOTIONDB_ASSIGN_OR_RETURN(const Eigen::VectorXd kept, space.MetricScales(dims));  // checks dims
  return (scaled * transform.leftCols(kept.size())).cast<float>();
}

}  // namespace motiondb
