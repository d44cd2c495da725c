#include "core/space/pose_encoder.h"

#include <vector>

#include "absl/strings/str_cat.h"
#include "core/space/heading.h"
#include "core/space/root_velocity.h"

namespace motiondb {
namespace {

namespace simd = Eigen::internal;
// Eigen's SIMD packet of doubles for this build (2 lanes with SSE2, 4 with AVX, 1 without).
using Packet = simd::packet_traits<double>::type;
constexpr int kLanes = simd::packet_traits<double>::size;

// Below this |(x, y, z)| the log map's factor angle / sin(angle / 2) is taken at its limit, 2.
constexpr double kSmallSine = 1e-12;

// The matrix M with M q = conj(reference) * q for quaternions as (w, x, y, z) column vectors.
Eigen::Matrix4d ConjugateProduct(const Quat& reference) {
  const double w = reference.w();
  const double x = -reference.x();
  const double y = -reference.y();
  const double z = -reference.z();
  Eigen::Matrix4d product;   // left multiplication by (w, x, y, z)
  product << w, -x, -y, -z,  //
      x, w, -z, y,           //
      y, z, w, -x,           //
      z, -y, x, w;
  return product;
}

// LogMap (rotation.h) for a packet of rotations (w, v) with sine = |v|: the factor f with
// rotation vector f * v, i.e. angle / sine with angle = 2 atan2(sine, |w|), negated when w < 0
// (the other hemisphere). Branch-free SIMD: std::atan2, one call per joint and frame, took most
// of the encoder's time. The arctangent is Cephes' atan, exact to rounding: the ratio of the
// smaller to the larger of sine and |w| is brought into [-tan(pi/8), tan(pi/8)] by
// atan(t) = pi/4 + atan((t - 1) / (t + 1)), where u + u z P(z) / Q(z), z = u^2, holds.
Packet LogMapFactor(const Packet& w, const Packet& sine) {
  const auto constant = [](double value) { return simd::pset1<Packet>(value); };
  // Horner's rule: ((value z + a) z + b) z + ...
  const auto polynomial = [&](Packet value, const Packet& z, double a, double b, double c,
                              double d) {
    value = simd::pmadd(value, z, constant(a));
    value = simd::pmadd(value, z, constant(b));
    value = simd::pmadd(value, z, constant(c));
    return simd::pmadd(value, z, constant(d));
  };
  constexpr double kMoreBits = 6.123233995736765886130e-17;  // pi/2 - (double)(pi/2)
  const Packet c = simd::pabs(w);
  const Packet low = simd::pmin(sine, c);
  const Packet high = simd::pmax(sine, c);
  const Packet reduce = simd::pcmp_lt(simd::pmul(constant(0.41421356237309504880), high), low);
  const Packet u = simd::pdiv(simd::pselect(reduce, simd::psub(low, high), low),
                              simd::pselect(reduce, simd::padd(low, high), high));
  const Packet z = simd::pmul(u, u);
  const Packet p = polynomial(constant(-8.750608600031904122785e-1), z, -1.615753718733365076637e1,
                              -7.500855792314704667340e1, -1.228866684490136173410e2,
                              -6.485021904942025371773e1);
  const Packet q =
      polynomial(simd::padd(z, constant(2.485846490142306297962e1)), z, 1.650270098316988542046e2,
                 4.328810604912902668951e2, 4.853903996359136964868e2, 1.945506571482613964425e2);
  const Packet atan =
      simd::padd(simd::pand(reduce, constant(0.78539816339744830962 + kMoreBits / 2)),
                 simd::padd(u, simd::pdiv(simd::pmul(simd::pmul(u, z), p), q)));
  const Packet half_angle = simd::pselect(
      simd::pcmp_lt(c, sine),
      simd::padd(simd::psub(constant(1.57079632679489661923), atan), constant(kMoreBits)), atan);
  const Packet factor = simd::pselect(
      simd::pcmp_lt(sine, constant(kSmallSine)), constant(2.0),
      simd::pdiv(simd::pmul(constant(2.0), half_angle), simd::pmax(sine, constant(kSmallSine))));
  return simd::pselect(simd::pcmp_lt(w, simd::pzero(w)), simd::pnegate(factor), factor);
}

}  // namespace

absl::Status ValidatePoseOptions(const PoseOptions& options) {
  if (options.yaw_rate_window < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("yaw-rate window must be at least 1 frame, got ", options.yaw_rate_window));
  }
  return absl::OkStatus();
}

int PoseDims(int joint_count, const PoseOptions& options) {
  if (!options.remove_heading) return 3 * joint_count;
  return 3 * joint_count + 1 + (options.root_velocity ? kRootVelocityDims : 0);
}

PoseRotations ComputePoseRotations(const Clip& clip, const PoseOptions& options) {
  PoseRotations pose{clip.rotations(), Eigen::VectorXd(), RowMatrixXd()};
  if (options.remove_heading) {
    const Eigen::VectorXd yaw = RemoveHeading(clip.skeleton(), &pose.rotations);
    pose.yaw_rate = YawRate(yaw, clip.fps(), options.yaw_rate_window);
    if (options.root_velocity) {
      pose.root_velocity = RootVelocity(clip, yaw, options.yaw_rate_window);
    }
  }
  return pose;
}

RowMatrixXd EncodePoses(const PoseRotations& pose, const RowMatrixXd& references) {
  const Eigen::Index frames = pose.rotations.rows();
  const Eigen::Index joints = references.rows();
  const bool has_yaw_rate = pose.yaw_rate.size() > 0;
  RowMatrixXd poses(frames, 3 * joints + (has_yaw_rate ? 1 : 0) + pose.root_velocity.cols());
  std::vector<Eigen::Matrix4d> to_relative;
  for (Eigen::Index j = 0; j < joints; ++j) {
    to_relative.push_back(ConjugateProduct(
        Quat(references(j, 0), references(j, 1), references(j, 2), references(j, 3))));
  }
  // One frame's relative rotations, a joint per row, and their sines and factors, padded to
  // whole packets with the identity (which gives a zero rotation vector).
  const Eigen::Index padded = (joints + kLanes - 1) / kLanes * kLanes;
  Eigen::Matrix<double, Eigen::Dynamic, 4> relative =
      Eigen::Matrix<double, Eigen::Dynamic, 4>::Zero(padded, 4);
  relative.col(0).setOnes();
  Eigen::VectorXd sine = Eigen::VectorXd::Zero(padded);
  Eigen::VectorXd factor(padded);
  for (Eigen::Index f = 0; f < frames; ++f) {
    const double* row = pose.rotations.row(f).data();
    for (Eigen::Index j = 0; j < joints; ++j) {
      relative.row(j).noalias() =
          (to_relative[j] * Eigen::Map<const Eigen::Vector4d>(row + 4 * j)).transpose();
      sine[j] = relative.row(j).tail<3>().norm();
    }
    for (Eigen::Index j = 0; j < padded; j += kLanes) {
      simd::pstoreu(factor.data() + j, LogMapFactor(simd::ploadu<Packet>(&relative(j, 0)),
                                                    simd::ploadu<Packet>(sine.data() + j)));
    }
    for (Eigen::Index j = 0; j < joints; ++j) {
      poses.block<1, 3>(f, 3 * j) = factor[j] * relative.row(j).tail<3>();
    }
  }
  if (has_yaw_rate) poses.col(3 * joints) = pose.yaw_rate;
  if (pose.root_velocity.size() > 0) poses.rightCols<kRootVelocityDims>() = pose.root_velocity;
  return poses;
}

RowMatrixXd DecodePoses(const Eigen::Ref<const RowMatrixXd>& poses, const RowMatrixXd& references) {
  const Eigen::Index frames = poses.rows();
  const Eigen::Index joints = references.rows();
  RowMatrixXd rotations(frames, 4 * joints);
  for (Eigen::Index j = 0; j < joints; ++j) {
    const Quat reference(references(j, 0), references(j, 1), references(j, 2), references(j, 3));
    for (Eigen::Index f = 0; f < frames; ++f) {
      Quat q = ExpMapAbout(poses.block<1, 3>(f, 3 * j).transpose(), reference);
      if (q.w() < 0.0) q.coeffs() = -q.coeffs();
      rotations.block<1, 4>(f, 4 * j) << q.w(), q.x(), q.y(), q.z();
    }
  }
  return rotations;
}

}  // namespace motiondb
