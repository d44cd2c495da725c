// A clip's coordinates for searching in a space: its motion curve at the space rate, multiplied by
// the space's metric scales (and by its search transform, a learned metric, when it has one),
// truncated to `dims` dimensions, as float32, so that plain Euclidean distance between rows is
// the space's search metric.
#ifndef MOTIONDB_CORE_SPACE_SEARCH_COORDINATES_H_
#define MOTIONDB_CORE_SPACE_SEARCH_COORDINATES_H_

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"
#include "core/space/motion_space.h"

namespace motiondb {

// `dims` -1 means all of the space's dimensions; `map` is the clip's skeleton's humanoid map in a
// canonical-bones space (MotionSpace::EncodeClip).
absl::StatusOr<RowMatrixXf> SearchCoordinates(const MotionSpace& space, const Clip& clip,
                                              int dims = -1, const HumanoidMap* map = nullptr);

// The same for pose vectors (n x space.dims(), MotionSpace::EncodeClip's), e.g. a query's
// poses mirrored.
absl::StatusOr<RowMatrixXf> SearchCoordinatesOfPoses(const MotionSpace& space,
                                                     const Eigen::Ref<const RowMatrixXd>& poses,
                                                     int dims = -1);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_SEARCH_COORDINATES_H_
