#include "core/motion/rotation.h"

#include <cmath>
#include <cstdint>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "absl/status/status.h"

namespace motiondb {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Below this vector norm the log/exp maps switch to their first-order series.
constexpr double kSmallAngle = 1e-12;

// std::round(v), halves away from zero and the sign of zero kept, without the libm call that
// std::round is on baseline x86-64 (no SSE4.1): NearestEulerTriple's plain rule unwraps six
// angles a call.
double Round(double v) {
  if (!(std::fabs(v) < 0x1p52)) return std::round(v);  // no fraction, or not finite
  // Toward zero, then the exact fraction left decides.
  const double toward_zero = std::copysign(static_cast<double>(static_cast<int64_t>(v)), v);
  const double fraction = v - toward_zero;
  if (fraction >= 0.5) return toward_zero + 1.0;
  if (fraction <= -0.5) return toward_zero - 1.0;
  return toward_zero;
}

// The value of `angle` + 2 pi k closest to `target`.
double UnwrapNear(double angle, double target) {
  return angle + kTwoPi * Round((target - angle) / kTwoPi);
}

}  // namespace

absl::string_view EulerOrderName(EulerOrder order) {
  switch (order) {
    case EulerOrder::kXYZ:
      return "XYZ";
    case EulerOrder::kXZY:
      return "XZY";
    case EulerOrder::kYXZ:
      return "YXZ";
    case EulerOrder::kYZX:
      return "YZX";
    case EulerOrder::kZXY:
      return "ZXY";
    case EulerOrder::kZYX:
      return "ZYX";
  }
  return "?";
}

std::array<int, 3> EulerAxes(EulerOrder order) {
  // A table, not a switch, so that it is inlined into EulerAngles (the BVH writer calls it for
  // every joint of every frame).
  static constexpr std::array<std::array<int, 3>, 6> kAxes = {
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};  // as kAllEulerOrders
  const auto index = static_cast<size_t>(order);
  return index < kAxes.size() ? kAxes[index] : kAxes[0];
}

std::optional<EulerOrder> EulerOrderFromAxes(const std::array<int, 3>& axes) {
  for (EulerOrder order : kAllEulerOrders) {
    if (EulerAxes(order) == axes) return order;
  }
  return std::nullopt;
}

Quat EulerToQuaternion(const Eigen::Vector3d& angles, EulerOrder order) {
  const std::array<int, 3> axes = EulerAxes(order);
  Quat q = Quat::Identity();
  for (int i = 0; i < 3; ++i) {
    const double half = 0.5 * angles[i];
    Quat step(std::cos(half), 0.0, 0.0, 0.0);
    step.vec()[axes[i]] = std::sin(half);
    q = q * step;
  }
  return q;
}

Eigen::Vector3d QuaternionToEuler(const Quat& q, EulerOrder order, const Eigen::Vector3d& near) {
  return NearestEulerTriple(EulerAngles(q, order), near);
}

Eigen::Vector3d EulerAngles(const Quat& q, EulerOrder order) {
  const std::array<int, 3> axes = EulerAxes(order);
  const int i = axes[0], j = axes[1], k = axes[2];
  // For R = R_i(a) R_j(b) R_k(c): R(i,k) = s sin b, with s = +1 for cyclic orders (XYZ, YZX,
  // ZXY) and -1 for the others; R(j,k) and R(k,k), R(i,j) and R(i,i) give a and c.
  const double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  const double cos_b = std::hypot(r(i, i), r(i, j));
  Eigen::Vector3d e;
  e[1] = std::atan2(s * r(i, k), cos_b);
  if (cos_b > 1e-10) {
    e[0] = std::atan2(-s * r(j, k), r(k, k));
    e[2] = std::atan2(-s * r(i, j), r(i, i));
  } else {
    // Gimbal lock: only a +/- c is determined; put it all in a.
    e[0] = std::atan2(s * r(k, j), r(j, j));
    e[2] = 0.0;
  }
  return e;
}

Eigen::Vector3d NearestEulerTriple(const Eigen::Vector3d& angles, const Eigen::Vector3d& near) {
  // (a, b, c) and (a + pi, pi - b, c + pi) are the same rotation; take the one nearest `near`.
  // Consecutive frames nearly always lie well within pi of each other in every angle: then
  // `angles` needs no turn (UnwrapNear adds a signed zero) and the other triple, pi - |a - near a|
  // and pi - |c - near c| away in a and c alone, is farther whenever `angles` is nearer than that
  // by a margin far above rounding. The BVH writer makes every joint of every frame continuous
  // in frame order; this answers the same, several times faster. Past it (a joint whose angles
  // have wound beyond +/-pi, a jump between frames) the plain rule below answers.
  const Eigen::Vector3d d = near - angles;
  if (d.cwiseAbs().maxCoeff() < 3.1) {
    const double other =
        (std::numbers::pi - std::fabs(d[0])) * (std::numbers::pi - std::fabs(d[0])) +
        (std::numbers::pi - std::fabs(d[2])) * (std::numbers::pi - std::fabs(d[2]));
    if (d.squaredNorm() < 0.999 * other) {
      return Eigen::Vector3d(angles[0] + std::copysign(0.0, d[0]),
                             angles[1] + std::copysign(0.0, d[1]),
                             angles[2] + std::copysign(0.0, d[2]));
    }
  }
  const Eigen::Vector3d alternative(angles[0] + std::numbers::pi, std::numbers::pi - angles[1],
                                    angles[2] + std::numbers::pi);
  Eigen::Vector3d best;
  double best_distance = INFINITY;
  for (const Eigen::Vector3d& candidate : {angles, alternative}) {
    Eigen::Vector3d unwrapped;
    for (int a = 0; a < 3; ++a) unwrapped[a] = UnwrapNear(candidate[a], near[a]);
    const double distance = (unwrapped - near).squaredNorm();
    if (distance < best_distance) {
      best_distance = distance;
      best = unwrapped;
    }
  }
  return best;
}

Quat Slerp(const Quat& a, const Quat& b, double t) { return a.slerp(t, b).normalized(); }

Eigen::Vector3d LogMap(const Quat& q) {
  const double sign = q.w() < 0.0 ? -1.0 : 1.0;
  const Eigen::Vector3d v = sign * q.vec();
  const double w = sign * q.w();
  const double s = v.norm();
  if (s < kSmallAngle) return 2.0 * v;
  return v * (2.0 * std::atan2(s, w) / s);
}

Quat ExpMap(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < kSmallAngle) {
    Quat q(1.0, 0.5 * v.x(), 0.5 * v.y(), 0.5 * v.z());
    return q.normalized();
  }
  const Eigen::Vector3d xyz = v * (std::sin(0.5 * angle) / angle);
  return Quat(std::cos(0.5 * angle), xyz.x(), xyz.y(), xyz.z());
}

Eigen::Vector3d LogMapAbout(const Quat& q, const Quat& reference) {
  return LogMap(reference.conjugate() * q);
}

Quat ExpMapAbout(const Eigen::Vector3d& v, const Quat& reference) { return reference * ExpMap(v); }

double AngleBetween(const Quat& a, const Quat& b) {
  const Quat d = a.conjugate() * b;
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

absl::StatusOr<Quat> MeanQuaternion(const Eigen::Ref<const RowMatrixXd>& wxyz) {
  if (wxyz.cols() != 4) {
    return absl::InvalidArgumentError("MeanQuaternion: expected 4 columns (w, x, y, z)");
  }
  if (wxyz.rows() == 0) return absl::InvalidArgumentError("MeanQuaternion: no samples");
  return MeanQuaternionOfScatter(wxyz.transpose() * wxyz);
}

absl::StatusOr<Quat> MeanQuaternionOfScatter(const Eigen::Matrix4d& scatter) {
  // The trace is the samples' summed squared norm: zero only without samples.
  if (scatter.trace() <= 0.0) return absl::InvalidArgumentError("MeanQuaternion: no samples");
  if (!scatter.allFinite()) {
    return absl::InvalidArgumentError("MeanQuaternion: samples are not finite");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(scatter);
  Eigen::Vector4d mean = solver.eigenvectors().col(3);  // eigenvalues ascend
  if (mean[0] < 0.0) mean = -mean;
  return Quat(mean[0], mean[1], mean[2], mean[3]).normalized();
}

}  // namespace motiondb
