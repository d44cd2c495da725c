#include "core/motion/rotation.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace motiondb {
namespace {

constexpr double kPi = std::numbers::pi;

// Elementary rotation matrices written out by hand, independent of the code under test.
Eigen::Matrix3d AxisMatrix(int axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix3d m;
  switch (axis) {
    case 0:
      m << 1, 0, 0, 0, c, -s, 0, s, c;
      break;
    case 1:
      m << c, 0, s, 0, 1, 0, -s, 0, c;
      break;
    default:
      m << c, -s, 0, s, c, 0, 0, 0, 1;
      break;
  }
  return m;
}

// Intrinsic composition in listed order: R = R_a0 * R_a1 * R_a2.
Eigen::Matrix3d IndependentMatrix(const Eigen::Vector3d& angles, const std::array<int, 3>& axes) {
  return AxisMatrix(axes[0], angles[0]) * AxisMatrix(axes[1], angles[1]) *
         AxisMatrix(axes[2], angles[2]);
}

Quat RandomQuat(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
}

class EulerOrderTest : public ::testing::TestWithParam<EulerOrder> {};

TEST_P(EulerOrderTest, MatchesIndependentMatrixConstruction) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  const auto axes = EulerAxes(GetParam());
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Vector3d angles(angle(rng), angle(rng), angle(rng));
    const Eigen::Matrix3d expected = IndependentMatrix(angles, axes);
    const Eigen::Matrix3d actual = EulerToQuaternion(angles, GetParam()).toRotationMatrix();
    ASSERT_LT((expected - actual).cwiseAbs().maxCoeff(), 1e-12) << angles.transpose();
  }
}

TEST_P(EulerOrderTest, DecompositionRecoversTheRotation) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 500; ++trial) {
    const Quat q = RandomQuat(rng);
    const Eigen::Vector3d angles = QuaternionToEuler(q, GetParam());
    EXPECT_LE(angles.cwiseAbs().maxCoeff(), kPi + 1e-12) << "nearest to zero";
    // Checked against the hand-written matrices, not the code's own composition.
    const Eigen::Matrix3d m = IndependentMatrix(angles, EulerAxes(GetParam()));
    ASSERT_LT((m - q.toRotationMatrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST_P(EulerOrderTest, DecompositionReturnsTheOriginalAnglesWhenNearThem) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> outer(-kPi + 0.01, kPi - 0.01);
  std::uniform_real_distribution<double> middle(-kPi / 2 + 0.01, kPi / 2 - 0.01);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Vector3d angles(outer(rng), middle(rng), outer(rng));
    const Eigen::Vector3d back =
        QuaternionToEuler(EulerToQuaternion(angles, GetParam()), GetParam(), angles);
    ASSERT_LT((back - angles).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST_P(EulerOrderTest, GimbalLockStillRecoversTheRotation) {
  for (double middle : {kPi / 2, -kPi / 2}) {
    for (double outer : {-2.0, -0.3, 0.0, 0.7, 2.5}) {
      const Eigen::Vector3d angles(outer, middle, 0.4);
      const Quat q = EulerToQuaternion(angles, GetParam());
      const Eigen::Vector3d back = QuaternionToEuler(q, GetParam());
      EXPECT_LT(AngleBetween(q, EulerToQuaternion(back, GetParam())), 1e-9) << angles.transpose();
    }
  }
}

TEST_P(EulerOrderTest, ConsecutiveFramesStayContinuousPastHalfATurn) {
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int step = 0; step <= 100; ++step) {
    const double t = step / 100.0;
    const Eigen::Vector3d angles(4.0 * t, 0.5 * std::sin(3 * t), -5.0 * t);  // beyond +/- pi
    const Eigen::Vector3d back =
        QuaternionToEuler(EulerToQuaternion(angles, GetParam()), GetParam(), previous);
    ASSERT_LT((back - angles).cwiseAbs().maxCoeff(), 1e-9) << "step " << step;
    previous = back;
  }
}

INSTANTIATE_TEST_SUITE_P(AllOrders, EulerOrderTest, ::testing::ValuesIn(kAllEulerOrders),
                         [](const auto& info) { return std::string(EulerOrderName(info.param)); });

// NearestEulerTriple's shortcut for nearby angles against the plain rule (both triples, each
// angle unwrapped by std::round, the nearer kept, the first on a tie): the same bits, signed
// zeros included, near and far, on and off the shortcut.
TEST(NearestEulerTriple, IsThePlainRuleBitForBit) {
  const auto plain = [](const Eigen::Vector3d& e, const Eigen::Vector3d& near) {
    const double pi = std::numbers::pi;
    Eigen::Vector3d best;
    double best_distance = INFINITY;
    for (const Eigen::Vector3d& candidate : {e, Eigen::Vector3d(e[0] + pi, pi - e[1], e[2] + pi)}) {
      Eigen::Vector3d unwrapped;
      for (int a = 0; a < 3; ++a) {
        unwrapped[a] = candidate[a] + 2 * pi * std::round((near[a] - candidate[a]) / (2 * pi));
      }
      const double distance = (unwrapped - near).squaredNorm();
      if (distance < best_distance) {
        best_distance = distance;
        best = unwrapped;
      }
    }
    return best;
  };
  const auto same_as_plain = [&](const Eigen::Vector3d& e,
                                 const Eigen::Vector3d& near) -> ::testing::AssertionResult {
    const Eigen::Vector3d got = NearestEulerTriple(e, near), want = plain(e, near);
    for (int a = 0; a < 3; ++a) {
      if (std::bit_cast<uint64_t>(got[a]) != std::bit_cast<uint64_t>(want[a])) {
        return ::testing::AssertionFailure()
               << "angle " << a << ": " << got[a] << " against " << want[a] << " for "
               << e.transpose() << " near " << near.transpose();
      }
    }
    return ::testing::AssertionSuccess();
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::normal_distribution<double> step;
  std::uniform_int_distribution<int> turns(-3, 3);
  for (int n = 0; n < 200000; ++n) {
    const Eigen::Vector3d e(angle(rng), angle(rng) / 2, angle(rng));
    // Near e (a frame's step, a turn or two away), or anywhere.
    const double scale = std::vector<double>{1e-3, 0.3, 1.5, 3.0}[n % 4];
    Eigen::Vector3d near = e + scale * Eigen::Vector3d(step(rng), step(rng), step(rng));
    if (n % 5 == 0) near += 2 * std::numbers::pi * Eigen::Vector3d(turns(rng), 0, turns(rng));
    if (n % 7 == 0) near = Eigen::Vector3d(angle(rng), angle(rng), angle(rng));
    ASSERT_TRUE(same_as_plain(e, near));
  }
  // Signed zeros and tiny values, each angle on its own: UnwrapNear adds a zero of the sign of
  // near - e, so -0 near +0 gives +0 and -0 near -0 gives -0.
  const double small[] = {0.0, -0.0, 1e-300, -1e-300};
  for (int combination = 0; combination < 4 * 4 * 4 * 4 * 4 * 4; ++combination) {
    Eigen::Vector3d e, near;
    for (int a = 0, rest = combination; a < 3; ++a, rest /= 16) {
      e[a] = small[rest % 4];
      near[a] = small[rest / 4 % 4];
    }
    ASSERT_TRUE(same_as_plain(e, near));
  }
  // Around the shortcut's bound and around the two triples' tie: near - e = s u, s found by
  // bisection where |s u|^2 is `share` times (pi - |s u_0|)^2 + (pi - |s u_2|)^2. That is the
  // other triple's distance when its middle angle, pi - e_1, is near's: e_1 = pi / 2, u_1 = 0.
  // Past the tie the plain rule takes the other triple; a shortcut whose bound let it answer
  // there would differ.
  int other_triples = 0;
  for (int n = 0; n < 4000; ++n) {
    const bool at_tie = n % 2 == 1;
    const double share = at_tie ? 1.0 : 0.999;
    const Eigen::Vector3d e(angle(rng), at_tie ? std::numbers::pi / 2 : angle(rng) / 2, angle(rng));
    const Eigen::Vector3d u =
        Eigen::Vector3d(step(rng), at_tie ? 0.0 : step(rng), step(rng)).normalized();
    const auto margin = [&](double s) {
      const double pi = std::numbers::pi;
      const Eigen::Vector3d d = s * u;
      return d.squaredNorm() - share * ((pi - std::fabs(d[0])) * (pi - std::fabs(d[0])) +
                                        (pi - std::fabs(d[2])) * (pi - std::fabs(d[2])));
    };
    double low = 0, high = 3.09 / u.cwiseAbs().maxCoeff();
    if (margin(high) < 0) continue;  // no tie before the shortcut's 3.1 limit
    for (int i = 0; i < 100; ++i) {
      (margin(0.5 * (low + high)) < 0 ? low : high) = 0.5 * (low + high);
    }
    for (const double offset : {-1e-6, -1e-12, 0.0, 1e-12, 1e-6}) {
      const Eigen::Vector3d near = e + (low + offset) * u;
      ASSERT_TRUE(same_as_plain(e, near));
      if (std::fabs(plain(e, near)[0] - e[0]) > 1) ++other_triples;
    }
  }
  EXPECT_GT(other_triples, 1000);  // the far side of the tie was reached
}

TEST(EulerOrder, NamesAndAxesAgree) {
  for (EulerOrder order : kAllEulerOrders) {
    const auto axes = EulerAxes(order);
    std::string name;
    for (int axis : axes) name += "XYZ"[axis];
    EXPECT_EQ(name, std::string(EulerOrderName(order)));
    EXPECT_EQ(EulerOrderFromAxes(axes), order);
  }
  EXPECT_FALSE(EulerOrderFromAxes({0, 0, 1}).has_value());
}

TEST(Slerp, InterpolatesAlongTheShorterArc) {
  const Quat a = Quat::Identity();
  const Quat b(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  const Quat expected(Eigen::AngleAxisd(kPi / 4, Eigen::Vector3d::UnitZ()));
  EXPECT_LT(AngleBetween(Slerp(a, b, 0.5), expected), 1e-12);
  // -b is the same rotation: the result must not take the long way round.
  const Quat negated(-b.w(), -b.x(), -b.y(), -b.z());
  EXPECT_LT(AngleBetween(Slerp(a, negated, 0.5), expected), 1e-12);
  EXPECT_LT(AngleBetween(Slerp(a, b, 0.0), a), 1e-12);
  EXPECT_LT(AngleBetween(Slerp(a, b, 1.0), b), 1e-12);
  EXPECT_NEAR(Slerp(a, b, 0.3).norm(), 1.0, 1e-12);
}

TEST(LogMap, IsAxisTimesAngleAndInvertsExpMap) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -0.5).normalized();
  const Quat q(Eigen::AngleAxisd(1.2, axis));
  EXPECT_LT((LogMap(q) - 1.2 * axis).norm(), 1e-12);
  const Quat negated(-q.w(), -q.x(), -q.y(), -q.z());
  EXPECT_LT((LogMap(negated) - LogMap(q)).norm(), 1e-12);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Quat r = RandomQuat(rng);
    EXPECT_LE(LogMap(r).norm(), kPi + 1e-12);
    EXPECT_LT(AngleBetween(ExpMap(LogMap(r)), r), 1e-12);
  }
}

TEST(LogMap, HandlesTinyAngles) {
  for (double angle : {0.0, 1e-15, 1e-9, 1e-6}) {
    const Quat q(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()));
    EXPECT_NEAR(LogMap(q).y(), angle, 1e-15);
    EXPECT_LT(AngleBetween(ExpMap(Eigen::Vector3d(0, angle, 0)), q), 1e-15);
  }
}

TEST(LogMapAbout, RotatesTheReferenceOut) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const Quat reference = RandomQuat(rng), q = RandomQuat(rng);
    EXPECT_LT(LogMapAbout(reference, reference).norm(), 1e-12);
    EXPECT_LT(AngleBetween(ExpMapAbout(LogMapAbout(q, reference), reference), q), 1e-12);
    // The distance from the reference is the rotation angle between them.
    EXPECT_NEAR(LogMapAbout(q, reference).norm(), AngleBetween(q, reference), 1e-9);
  }
}

RowMatrixXd Rows(const std::vector<Quat>& quats) {
  RowMatrixXd m(quats.size(), 4);
  for (size_t i = 0; i < quats.size(); ++i) m.row(i) << quats[i].w(), quats[i].vec().transpose();
  return m;
}

TEST(MeanQuaternion, SymmetricSpreadAveragesToTheCentre) {
  const Quat centre(Eigen::AngleAxisd(2.0, Eigen::Vector3d(0.3, -1, 0.2).normalized()));
  std::vector<Quat> samples;
  for (int axis = 0; axis < 3; ++axis) {
    for (double angle : {-0.4, 0.4}) {
      samples.push_back(centre * Quat(Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(axis))));
    }
  }
  absl::StatusOr<Quat> mean = MeanQuaternion(Rows(samples));
  ASSERT_TRUE(mean.ok()) << mean.status();
  EXPECT_LT(AngleBetween(*mean, centre), 1e-9);
  EXPECT_GE(mean->w(), 0.0);
}

TEST(MeanQuaternion, IgnoresTheSignOfEachSample) {
  std::mt19937 rng(9);
  const Quat centre = RandomQuat(rng);
  std::normal_distribution<double> small(0.0, 0.2);
  std::vector<Quat> samples, flipped;
  for (int i = 0; i < 50; ++i) {
    const Quat q = centre * ExpMap(Eigen::Vector3d(small(rng), small(rng), small(rng)));
    samples.push_back(q);
    flipped.push_back(i % 2 ? Quat(-q.w(), -q.x(), -q.y(), -q.z()) : q);
  }
  const Quat a = *MeanQuaternion(Rows(samples));
  const Quat b = *MeanQuaternion(Rows(flipped));
  EXPECT_LT(AngleBetween(a, b), 1e-12);
  // For a tight cluster, the sign-aligned arithmetic mean is a close independent estimate.
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const Quat& q : samples) {
    Eigen::Vector4d v(q.w(), q.x(), q.y(), q.z());
    if (v.dot(Eigen::Vector4d(centre.w(), centre.x(), centre.y(), centre.z())) < 0) v = -v;
    sum += v;
  }
  sum.normalize();
  EXPECT_LT(AngleBetween(a, Quat(sum[0], sum[1], sum[2], sum[3])), 1e-3);
  EXPECT_LT(AngleBetween(a, centre), 0.15);
}

TEST(MeanQuaternion, RejectsBadInput) {
  EXPECT_EQ(MeanQuaternion(RowMatrixXd(0, 4)).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(MeanQuaternion(RowMatrixXd::Ones(3, 3)).status().code(),
            absl::StatusCode::kInvalidArgument);
  RowMatrixXd nan = RowMatrixXd::Ones(2, 4);
  nan(1, 2) = NAN;
  EXPECT_EQ(MeanQuaternion(nan).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(MeanQuaternionOfScatter(Eigen::Matrix4d::Zero()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(AngleBetween, IsSignInvariantAndExact) {
  const Quat a(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  const Quat b(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(AngleBetween(a, b), 0.8, 1e-12);
  EXPECT_NEAR(AngleBetween(a, Quat(-b.w(), -b.x(), -b.y(), -b.z())), 0.8, 1e-12);
  EXPECT_NEAR(AngleBetween(a, a), 0.0, 1e-15);
}

}  // namespace
}  // namespace motiondb
