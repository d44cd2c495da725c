// The operators hold rotations as rows of numbers, four a joint (w, x, y, z): frames x 4 * joints.
// Reading and writing one quaternion there.
#ifndef MOTIONDB_CORE_OPS_INTERNAL_QUAT_ROWS_H_
#define MOTIONDB_CORE_OPS_INTERNAL_QUAT_ROWS_H_

#include <Eigen/Core>

#include "core/motion/matrix.h"
#include "core/motion/rotation.h"

namespace motiondb::ops_internal {

// The quaternion at `row`, columns `column`..`column` + 3.
inline Quat QuatAt(const Eigen::Ref<const RowMatrixXd>& rows, Eigen::Index row,
                   Eigen::Index column) {
  const auto q = rows.block<1, 4>(row, column);
  return Quat(q[0], q[1], q[2], q[3]);
}

// Writes `q` there with w >= 0: q and -q are one rotation, and one sign keeps the rows
// comparable number by number.
inline void SetQuatAt(const Quat& q, Eigen::Ref<RowMatrixXd> rows, Eigen::Index row,
                      Eigen::Index column) {
  const double sign = q.w() < 0.0 ? -1.0 : 1.0;
  rows.block<1, 4>(row, column) << sign * q.w(), sign * q.x(), sign * q.y(), sign * q.z();
}

}  // namespace motiondb::ops_internal

#endif  // MOTIONDB_CORE_OPS_INTERNAL_QUAT_ROWS_H_
