// Rotation utilities: Euler angles in the six intrinsic orders, slerp, log/exp maps about a
// reference orientation, and the sample mean of unit quaternions (thesis Algorithm 2).
//
// Quaternions are Eigen::Quaterniond; stored blocks (see Clip) use w, x, y, z order.
// All functions are pure and thread-safe.
#ifndef MOTIONDB_CORE_MOTION_ROTATION_H_
#define MOTIONDB_CORE_MOTION_ROTATION_H_

#include <array>
#include <optional>
#include "absl/strings/string_view.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"

namespace motiondb {

using Quat = Eigen::Quaterniond;

// The order in which three rotation channels are listed, e.g. kZXY for
// "Zrotation Xrotation Yrotation". Rotations compose intrinsically in that order:
// q = q_Z(a0) * q_X(a1) * q_Y(a2), so a vector is rotated by the last-listed axis first.
enum class EulerOrder { kXYZ, kXZY, kYXZ, kYZX, kZXY, kZYX };

inline constexpr std::array<EulerOrder, 6> kAllEulerOrders = {EulerOrder::kXYZ, EulerOrder::kXZY,
                                                              EulerOrder::kYXZ, EulerOrder::kYZX,
                                                              EulerOrder::kZXY, EulerOrder::kZYX};

// "XYZ", "ZXY", ...
absl::string_view EulerOrderName(EulerOrder order);
// The axis indices (0 = X, 1 = Y, 2 = Z) in listed order.
std::array<int, 3> EulerAxes(EulerOrder order);
// The order whose axes are `axes` (a permutation of 0, 1, 2), or nullopt.
std::optional<EulerOrder> EulerOrderFromAxes(const std::array<int, 3>& axes);

// Angles in radians, angles[i] about axis EulerAxes(order)[i].
Quat EulerToQuaternion(const Eigen::Vector3d& angles, EulerOrder order);

// The Euler angles of q in `order`. Of the equivalent triples (a, b, c) and
// (a + pi, pi - b, c + pi), each angle unwrapped by multiples of 2 pi, returns the one closest to
// `near`, which keeps consecutive frames continuous when exporting a clip. The same as
// NearestEulerTriple(EulerAngles(q, order), near).
Eigen::Vector3d QuaternionToEuler(const Quat& q, EulerOrder order,
                                  const Eigen::Vector3d& near = Eigen::Vector3d::Zero());
// The two halves of QuaternionToEuler, so that a clip's frames can be decomposed in parallel and
// made continuous after: the Euler angles of q in `order`, each in [-pi, pi] ...
Eigen::Vector3d EulerAngles(const Quat& q, EulerOrder order);
// ... and of the triples equivalent to `angles`, the one closest to `near`.
Eigen::Vector3d NearestEulerTriple(const Eigen::Vector3d& angles, const Eigen::Vector3d& near);

// Spherical linear interpolation along the shorter arc (q and -q are the same rotation).
Quat Slerp(const Quat& a, const Quat& b, double t);

// Log map: the rotation vector (unit axis times angle in radians, angle in [0, pi]) of q,
// taken in the hemisphere w >= 0 so that q and -q map to the same vector.
Eigen::Vector3d LogMap(const Quat& q);
// Inverse of LogMap: the unit quaternion rotating by |v| radians about v.
Quat ExpMap(const Eigen::Vector3d& v);

// Linearisation about a reference orientation (thesis 3.2.1): LogMap(conj(reference) * q).
Eigen::Vector3d LogMapAbout(const Quat& q, const Quat& reference);
// Inverse of LogMapAbout: reference * ExpMap(v).
Quat ExpMapAbout(const Eigen::Vector3d& v, const Quat& reference);

// The angle in [0, pi] of the rotation taking a to b; sign-invariant in both arguments.
double AngleBetween(const Quat& a, const Quat& b);

// Sample mean of unit quaternions (thesis Algorithm 2, after Johnson): the eigenvector of the
// largest eigenvalue of sum q q^T, returned with w >= 0. Invariant to the sign of every sample.
// `wxyz` holds one quaternion per row as w, x, y, z. Fails on an empty set.
absl::StatusOr<Quat> MeanQuaternion(const Eigen::Ref<const RowMatrixXd>& wxyz);
// The same mean from the samples' scatter sum q q^T, which can be summed a batch at a time.
// Fails on a zero scatter (no samples).
absl::StatusOr<Quat> MeanQuaternionOfScatter(const Eigen::Matrix4d& scatter);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_ROTATION_H_
