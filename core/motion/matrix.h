// Batch-first dense types shared by the motion engine: one row per frame (or sample).
#ifndef MOTIONDB_CORE_MOTION_MATRIX_H_
#define MOTIONDB_CORE_MOTION_MATRIX_H_

#include <Eigen/Core>

namespace motiondb {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_MATRIX_H_
