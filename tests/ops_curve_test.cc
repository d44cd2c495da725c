// The curve operators (core/ops), checked against their closed forms: the gate of fig. 5.2,
// scaling and translation (5.3-5.4), Haar smoothing (5.5.1), the planar blend (4.2), Hermite
// gap filling (4.3) and the time-aligned blend (7.2.3).
#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/ops/aligned_blend.h"
#include "core/ops/edit_scope.h"
#include "core/ops/gap_fill.h"
#include "core/ops/planar_blend.h"
#include "core/ops/projected_mean.h"
#include "core/ops/scaling.h"
#include "core/ops/translation.h"
#include "core/ops/wavelet_smoothing.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

constexpr double kRate = 10.0;  // frames per second of the test curves

// A smooth curve of `frames` frames and `dims` dimensions: sines of several frequencies.
RowMatrixXd Wave(int frames, int dims) {
  RowMatrixXd curve(frames, dims);
  for (int f = 0; f < frames; ++f) {
    for (int d = 0; d < dims; ++d) {
      curve(f, d) = (1.0 + d) * std::sin(0.07 * (d + 1) * f + d) + 0.5 * d;
    }
  }
  return curve;
}

std::string MessageOf(const absl::Status& status) { return std::string(status.message()); }

TEST(EditScopeTest, TheGateIsZeroOutsideItsRampsOneInsideAndLinearOnThem) {
  const Gate gate{.start_s = 3.0, .end_s = 5.0, .lead_in_s = 1.0, .lead_out_s = 2.0};
  const Eigen::VectorXd g = GateEnvelope(gate, 101, kRate);  // t = 0 .. 10 s
  for (int k = 0; k <= 100; ++k) {
    const double t = k / kRate;
    if (t <= 2.0 || t >= 7.0) {
      EXPECT_EQ(g[k], 0.0) << "t = " << t;
    }
    if (t >= 3.0 && t <= 5.0) {
      EXPECT_EQ(g[k], 1.0) << "t = " << t;
    }
  }
  EXPECT_NEAR(g[25], 0.5, 1e-12);   // halfway up the lead-in
  EXPECT_NEAR(g[60], 0.5, 1e-12);   // halfway down the lead-out
  EXPECT_NEAR(g[55], 0.75, 1e-12);  // a quarter of the way down
  // Without ramps the gate is a box.
  const Eigen::VectorXd box = GateEnvelope({.start_s = 1.0, .end_s = 2.0}, 31, kRate);
  EXPECT_EQ(box.sum(), 11.0);
  EXPECT_EQ(box[9], 0.0);
  EXPECT_EQ(box[21], 0.0);
}

TEST(EditScopeTest, OnlyTheChosenDimensionsChangeAndBadScopesAreNamed) {
  const RowMatrixXd original = Wave(20, 4);
  const RowMatrixXd edited = original.array() + 1.0;
  const RowMatrixXd result = ApplyScope({.dims = {1, 3}}, original, edited, kRate);
  EXPECT_EQ(result.col(0), original.col(0));
  EXPECT_EQ(result.col(2), original.col(2));
  EXPECT_EQ(result.col(1), edited.col(1));
  EXPECT_EQ(result.col(3), edited.col(3));

  EXPECT_THAT(MessageOf(ValidateEditScope({.dims = {4}}, 4)), HasSubstr("dims[0]"));
  EXPECT_THAT(MessageOf(ValidateEditScope({.dims = {1, 1}}, 4)), HasSubstr("dims[1]"));
  EXPECT_THAT(MessageOf(ValidateEditScope({.gate = Gate{.start_s = 2, .end_s = 1}}, 4)),
              HasSubstr("gate.end_s"));
  EXPECT_THAT(MessageOf(ValidateEditScope({.gate = Gate{.lead_in_s = std::nan("")}}, 4)),
              HasSubstr("gate.lead_in_s"));
  EXPECT_THAT(MessageOf(ValidateEditScope({.gate = Gate{.lead_out_s = -1}}, 4)),
              HasSubstr("gate.lead_out_s"));
}

TEST(ScalingTest, FactorOneIsTheIdentityAndTheCentresBehave) {
  const RowMatrixXd curve = Wave(40, 5);
  for (const ScaleCentre centre : {ScaleCentre::kOrigin, ScaleCentre::kSelectionMean}) {
    const absl::StatusOr<RowMatrixXd> same =
        ScaleCurve(curve, kRate, {.factor = 1.0, .centre = centre});
    ASSERT_TRUE(same.ok()) << same.status();
    EXPECT_TRUE(same->isApprox(curve, 1e-15));
  }
  const absl::StatusOr<RowMatrixXd> doubled = ScaleCurve(curve, kRate, {.factor = 2.0});
  ASSERT_TRUE(doubled.ok());
  EXPECT_TRUE(doubled->isApprox(2.0 * curve, 1e-15));
  // About the selection's mean, the mean stays put and the spread doubles.
  const absl::StatusOr<RowMatrixXd> local =
      ScaleCurve(curve, kRate, {.factor = 2.0, .centre = ScaleCentre::kSelectionMean});
  ASSERT_TRUE(local.ok());
  const Eigen::RowVectorXd mean = curve.colwise().mean();
  EXPECT_TRUE(local->colwise().mean().isApprox(mean, 1e-12));
  EXPECT_TRUE((local->rowwise() - mean).isApprox(2.0 * (curve.rowwise() - mean), 1e-12));
}

TEST(ScalingTest, TheSigmoidScalesOnlyWhatLiesBeyondItsThreshold) {
  RowMatrixXd curve(2, 2);
  curve << 0.1, 0.0,  // near the origin
      3.0, 0.0;       // far from it
  const absl::StatusOr<RowMatrixXd> scaled = ScaleCurve(
      curve, kRate, {.factor = 2.0, .sigmoid = Sigmoid{.threshold = 1.0, .width = 0.05}});
  ASSERT_TRUE(scaled.ok());
  EXPECT_NEAR((*scaled)(0, 0), 0.1, 1e-6);
  EXPECT_NEAR((*scaled)(1, 0), 6.0, 1e-6);
  EXPECT_NEAR(SigmoidAt({.threshold = 1.0, .width = 0.05}, 1.0), 0.5, 1e-15);
}

TEST(ScalingTest, TheGateConfinesTheEditAndBadParametersAreNamed) {
  const RowMatrixXd curve = Wave(50, 3);
  const Gate gate{.start_s = 2.0, .end_s = 3.0, .lead_in_s = 0.5, .lead_out_s = 0.5};
  const absl::StatusOr<RowMatrixXd> scaled =
      ScaleCurve(curve, kRate, {.factor = 3.0, .scope = {.gate = gate}});
  ASSERT_TRUE(scaled.ok());
  for (int f = 0; f < 50; ++f) {
    const double t = f / kRate;
    if (t <= 1.5 || t >= 3.5) {
      EXPECT_EQ(scaled->row(f), curve.row(f)) << "t = " << t;
    }
    if (t >= 2.0 && t <= 3.0) {
      EXPECT_TRUE(scaled->row(f).isApprox(3.0 * curve.row(f), 1e-12));
    }
  }
  EXPECT_THAT(MessageOf(ScaleCurve(curve, kRate, {.factor = std::nan("")}).status()),
              HasSubstr("factor"));
  EXPECT_THAT(MessageOf(ScaleCurve(curve, kRate, {.sigmoid = Sigmoid{.width = 0}}).status()),
              HasSubstr("sigmoid.width"));
  // A gate past the curve's end selects nothing to take the mean of.
  EXPECT_THAT(MessageOf(ScaleCurve(curve, kRate,
                                   {.centre = ScaleCentre::kSelectionMean,
                                    .scope = {.gate = Gate{.start_s = 60, .end_s = 70}}})
                            .status()),
              HasSubstr("gate"));
}

TEST(TranslationTest, TowardAPoseMovesTheMeanAndAlongAnAxisMovesByIt) {
  const RowMatrixXd curve = Wave(30, 4);
  RowMatrixXd target(1, 4);
  target << 5, -1, 2, 0;
  const absl::StatusOr<RowMatrixXd> onto =
      TranslateCurve(curve, kRate, target, {.mode = TranslateMode::kTowardPose, .amount = 1.0});
  ASSERT_TRUE(onto.ok()) << onto.status();
  EXPECT_TRUE(onto->colwise().mean().isApprox(target.row(0), 1e-12));
  // The motion's shape is kept: every frame moved by one vector.
  const RowMatrixXd moved = *onto - curve;
  for (int f = 1; f < 30; ++f) EXPECT_TRUE(moved.row(f).isApprox(moved.row(0), 1e-12));

  RowMatrixXd axis(2, 4);
  axis << 0, 0, 0, 0,  //
      1, 2, 3, 4;
  const absl::StatusOr<RowMatrixXd> along =
      TranslateCurve(curve, kRate, axis, {.mode = TranslateMode::kAlongAxis, .amount = 0.5});
  ASSERT_TRUE(along.ok());
  EXPECT_TRUE((*along - curve).row(7).isApprox(0.5 * axis.row(1), 1e-12));
  const absl::StatusOr<RowMatrixXd> nothing =
      TranslateCurve(curve, kRate, axis, {.mode = TranslateMode::kAlongAxis, .amount = 0.0});
  EXPECT_EQ(*nothing, curve);

  EXPECT_THAT(MessageOf(TranslateCurve(curve, kRate, axis, {}).status()), HasSubstr("poses"));
  EXPECT_THAT(MessageOf(TranslateCurve(curve, kRate, target, {.amount = INFINITY}).status()),
              HasSubstr("amount"));
  EXPECT_THAT(MessageOf(TranslateCurve(curve, kRate, RowMatrixXd::Zero(1, 5), {}).status()),
              HasSubstr("poses"));
}

TEST(ProjectedMeanTest, WeighsFramesAndRefusesNoWeight) {
  RowMatrixXd points(3, 2);
  points << 0, 0, 2, 2, 4, 8;
  EXPECT_TRUE(ProjectedMean(points, Eigen::VectorXd())->isApprox(Eigen::RowVector2d(2, 10.0 / 3)));
  EXPECT_TRUE(ProjectedMean(points, Eigen::Vector3d(0, 1, 1))->isApprox(Eigen::RowVector2d(3, 5)));
  EXPECT_THAT(MessageOf(ProjectedMean(points, Eigen::Vector3d(0, 0, 0)).status()),
              HasSubstr("weights"));
}

TEST(SmoothingTest, LevelZeroIsTheIdentityAndTheTopLevelTheMean) {
  for (const int frames : {1, 2, 37, 64}) {
    const RowMatrixXd curve = Wave(frames, 3);
    const absl::StatusOr<RowMatrixXd> same = SmoothCurve(curve, {.level = 0.0});
    ASSERT_TRUE(same.ok());
    EXPECT_EQ(*same, curve);
  }
  const RowMatrixXd curve = Wave(64, 3);
  const absl::StatusOr<RowMatrixXd> flat = SmoothCurve(curve, {.level = 6.0});
  ASSERT_TRUE(flat.ok());
  for (int f = 0; f < 64; ++f) EXPECT_TRUE(flat->row(f).isApprox(curve.colwise().mean(), 1e-12));
  EXPECT_EQ(*SmoothCurve(curve, {.level = 40.0}), *flat);  // past the top: the mean still
}

TEST(SmoothingTest, FractionalLevelsInterpolateAndSmoothingRemovesNoise) {
  const RowMatrixXd clean = Wave(100, 2);
  std::mt19937_64 generator(7);
  std::normal_distribution<double> noise(0.0, 0.2);
  RowMatrixXd noisy = clean;
  for (Eigen::Index i = 0; i < noisy.size(); ++i) noisy.data()[i] += noise(generator);
  const auto at = [&](double level) { return *SmoothCurve(noisy, {.level = level}); };
  EXPECT_TRUE(at(1.25).isApprox(0.75 * at(1.0) + 0.25 * at(2.0), 1e-12));
  // Small levels take the noise out; the top level takes the motion too.
  const double raw = (noisy - clean).norm();
  EXPECT_LT((at(1.0) - clean).norm(), 0.8 * raw);
  EXPECT_LT((at(2.0) - clean).norm(), 0.6 * raw);
  EXPECT_GT((at(7.0) - clean).norm(), raw);
  // Roughness (second differences) falls level by level.
  const auto roughness = [](const RowMatrixXd& c) {
    return (c.bottomRows(c.rows() - 2) - 2 * c.middleRows(1, c.rows() - 2) +
            c.topRows(c.rows() - 2))
        .norm();
  };
  EXPECT_LT(roughness(at(0.5)), roughness(noisy));
  EXPECT_LT(roughness(at(1.5)), roughness(at(0.5)));
  EXPECT_THAT(MessageOf(SmoothCurve(noisy, {.level = -0.5}).status()), HasSubstr("level"));
  EXPECT_THAT(MessageOf(SmoothCurve(noisy, {.level = std::nan("")}).status()), HasSubstr("level"));
}

// A frame count that is not a power of two is supersampled first (5.5.1); what supersampling
// changes must not come back as noise. White noise about a constant: each level leaves less of
// it (within 1%: between two whole levels the result is their linear mix, whose norm need not
// fall strictly), a whole level s no more than the mean of a block of 2^s supersampled samples
// would (sigma / sqrt(2^s n / N)), and past the top the curve is flat.
TEST(SmoothingTest, NoiseFallsLevelByLevelWhateverTheFrameCount) {
  for (const int frames : {65, 100, 300}) {
    int size = 1;
    while (size < frames) size *= 2;
    const RowMatrixXd clean = RowMatrixXd::Constant(frames, 2, 1.5);
    std::mt19937_64 generator(frames);
    std::normal_distribution<double> noise(0.0, 0.2);
    RowMatrixXd noisy = clean;
    for (Eigen::Index i = 0; i < noisy.size(); ++i) noisy.data()[i] += noise(generator);
    const auto error = [&](double level) {
      const absl::StatusOr<RowMatrixXd> smoothed = SmoothCurve(noisy, {.level = level});
      EXPECT_TRUE(smoothed.ok()) << smoothed.status();
      return smoothed.ok() ? (*smoothed - clean).norm() : 0.0;
    };
    const double raw = (noisy - clean).norm();
    EXPECT_EQ(error(0.0), raw);
    double previous = raw;
    for (double level = 0.25; level <= 12.0; level += 0.25) {
      const double left = error(level);
      EXPECT_LT(left, raw) << frames << " frames, level " << level;
      EXPECT_LE(left, 1.01 * previous) << frames << " frames, level " << level;
      previous = left;
    }
    for (int level = 1; level <= 4; ++level) {
      const double block_frames = std::ldexp(1.0, level) * frames / size;
      EXPECT_LT(error(level), raw / std::sqrt(block_frames))
          << frames << " frames, level " << level;
    }
    const RowMatrixXd flat = *SmoothCurve(noisy, {.level = 40.0});
    EXPECT_EQ((flat.rowwise() - flat.row(0)).cwiseAbs().maxCoeff(), 0.0) << frames << " frames";
  }
}

TEST(PlanarBlendTest, WeightsSumToOneAndEachPoseIsHitAtItsPoint) {
  const RowMatrixXd poses = Wave(4, 6);
  RowMatrixXd plane(4, 2);
  plane << 0, 0, 1, 0, 0, 1, 1, 1;
  RowMatrixXd points(6, 2);
  points << 0, 0, 1, 0, 0, 1, 1, 1, 0.5, 0.5, 0.2, 0.7;
  const absl::StatusOr<PlanarBlend> exact = BlendOnPlane(poses, plane, points, {.epsilon = 0.0});
  ASSERT_TRUE(exact.ok()) << exact.status();
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(exact->weights.row(k).sum(), 1.0, 1e-12);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(exact->coordinates.row(i).isApprox(poses.row(i), 1e-15));
  // The centre weighs the four corners alike (eq. 4.2).
  EXPECT_TRUE(exact->weights.row(4).isApprox(Eigen::RowVector4d::Constant(0.25), 1e-12));
  EXPECT_TRUE(exact->coordinates.row(4).isApprox(poses.colwise().mean(), 1e-12));
  // eq. 4.2 by hand for the last point.
  Eigen::RowVector4d w;
  for (int i = 0; i < 4; ++i) w[i] = 1.0 / (points.row(5) - plane.row(i)).norm();
  EXPECT_TRUE(exact->weights.row(5).isApprox(w / w.sum(), 1e-12));

  // With the default epsilon a pose's own point gives it nearly all the weight.
  const absl::StatusOr<PlanarBlend> soft = BlendOnPlane(poses, plane, points.topRows(1));
  EXPECT_GT(soft->weights(0, 0), 0.99);
  EXPECT_TRUE(soft->coordinates.row(0).isApprox(poses.row(0), 1e-2));

  EXPECT_THAT(MessageOf(BlendOnPlane(poses, plane.topRows(3), points).status()),
              HasSubstr("plane"));
  EXPECT_THAT(MessageOf(BlendOnPlane(poses, plane, points, {.epsilon = -1}).status()),
              HasSubstr("epsilon"));
  EXPECT_THAT(MessageOf(BlendOnPlane(poses.topRows(0), plane.topRows(0), points).status()),
              HasSubstr("poses"));
  EXPECT_THAT(MessageOf(BlendOnPlane(poses, plane, RowMatrixXd(0, 2)).status()),
              HasSubstr("points"));
}

// Eq. 4.2's weights at the extremes of a double: a point 1e-200 from a pose (whose squared
// distance underflows) and points 1e200 away (whose squared distances overflow) still give
// finite weights summing to 1: the nearest pose all of it, or the far poses alike.
TEST(PlanarBlendTest, WeightsStayFiniteAtTinyAndHugeDistances) {
  const RowMatrixXd poses = Wave(3, 4);
  RowMatrixXd plane(3, 2);
  plane << 0, 0, 1, 0, 0, 1;
  RowMatrixXd points(4, 2);
  points << 1e-200, 0, 1e200, 0, -1e200, 1e200, 1e-200, 1e200;
  for (const double epsilon : {0.0, 1e-6}) {
    const absl::StatusOr<PlanarBlend> blend =
        BlendOnPlane(poses, plane, points, {.epsilon = epsilon});
    ASSERT_TRUE(blend.ok()) << blend.status();
    ASSERT_TRUE(blend->weights.allFinite()) << blend->weights;
    ASSERT_TRUE(blend->coordinates.allFinite());
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(blend->weights.row(k).sum(), 1.0, 1e-12) << k;
    // With epsilon the pose's own point is 1e-3 from it in eq. 4.2's terms, the others about 1.
    EXPECT_GT(blend->weights(0, 0), epsilon == 0.0 ? 1.0 - 1e-12 : 0.99) << "epsilon " << epsilon;
    for (int k = 1; k < 4; ++k) {
      EXPECT_TRUE(blend->weights.row(k).isApprox(Eigen::RowVector3d::Constant(1.0 / 3), 1e-9))
          << "epsilon " << epsilon << ", point " << k << ": " << blend->weights.row(k);
    }
  }
}

TEST(GapFillTest, TheHermiteCurveHitsItsEndsAndTheirDerivatives) {
  const Eigen::RowVector3d p0(1, 2, 3), p1(-2, 0, 5), d0(4, -1, 0), d1(0, 2, -3);
  for (const double v : {0.0, 0.4, 1.0}) {
    const double h = 1e-6;
    Eigen::VectorXd t(4);
    t << 0.0, h, 1.0 - h, 1.0;
    const RowMatrixXd x = HermiteCurve(p0, p1, d0, d1, v, t);
    EXPECT_TRUE(x.row(0).isApprox(p0, 1e-15));
    EXPECT_TRUE(x.row(3).isApprox(p1, 1e-15));
    // One-sided differences, exact to O(h).
    EXPECT_LT(((x.row(1) - x.row(0)) / h - v * d0).norm(), 1e-4) << "v = " << v;
    EXPECT_LT(((x.row(3) - x.row(2)) / h - v * d1).norm(), 1e-4) << "v = " << v;
  }
}

TEST(GapFillTest, MotionAtConstantVelocityContinuesAcrossTheGap) {
  // Two pieces of one straight line at one speed, 5 frames apart.
  const Eigen::RowVector2d velocity(0.3, -0.1);
  RowMatrixXd before(10, 2), after(10, 2);
  for (int f = 0; f < 10; ++f) {
    before.row(f) = f * velocity;
    after.row(f) = (f + 15) * velocity;
  }
  for (const GapMethod method : {GapMethod::kHermite, GapMethod::kLinear}) {
    const absl::StatusOr<RowMatrixXd> gap = FillGap(before, after, {.frames = 5, .method = method});
    ASSERT_TRUE(gap.ok()) << gap.status();
    ASSERT_EQ(gap->rows(), 5);
    for (int k = 0; k < 5; ++k) EXPECT_TRUE(gap->row(k).isApprox((10 + k) * velocity, 1e-12));
  }
  // A curved path: the Hermite gap leaves the first clip at its own velocity, the line does not.
  for (int f = 0; f < 10; ++f) {
    after(f, 0) = 3.0 + 0.3 * f;
    after(f, 1) = 2.0;
  }
  const RowMatrixXd hermite = *FillGap(before, after, {.frames = 9});
  const RowMatrixXd line = *FillGap(before, after, {.frames = 9, .method = GapMethod::kLinear});
  const auto jump = [&](const RowMatrixXd& gap) {
    return ((gap.row(0) - before.row(9)) - velocity).norm();
  };
  EXPECT_LT(jump(hermite), 0.5 * jump(line));
  const RowMatrixXd damped = *FillGap(before, after, {.frames = 9, .damping = 0.0});
  EXPECT_GT(jump(damped), jump(hermite));

  EXPECT_THAT(MessageOf(FillGap(before, after, {.frames = 0}).status()), HasSubstr("frames"));
  EXPECT_THAT(MessageOf(FillGap(before, after, {.damping = 1.5}).status()), HasSubstr("damping"));
  EXPECT_THAT(MessageOf(FillGap(before, after, {.derivative_smoothing = -1}).status()),
              HasSubstr("derivative_smoothing"));
  EXPECT_THAT(MessageOf(FillGap(before, RowMatrixXd::Zero(3, 3)).status()), HasSubstr("after"));
}

// Smoothing before the finite difference (4.3) must not flatten the ends: a clip moving at
// constant speed keeps its speed at both ends at every level (the curve is continued past the
// end by odd reflection, so the end is no block's edge). Levels beyond the reflected curve's
// own make it flat, and a clip of one frame has no velocity.
TEST(GapFillTest, SmoothedEndVelocitiesKeepARampsSlope) {
  RowMatrixXd ramp(40, 2);
  for (int f = 0; f < 40; ++f) ramp.row(f) << f, 3.0 - 0.5 * f;
  const Eigen::RowVector2d slope(1.0, -0.5);
  for (const double level : {0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0}) {
    for (const CurveEnd end : {CurveEnd::kFirst, CurveEnd::kLast}) {
      const absl::StatusOr<Eigen::RowVectorXd> velocity = EndVelocity(ramp, {.level = level}, end);
      ASSERT_TRUE(velocity.ok()) << velocity.status();
      EXPECT_TRUE(velocity->isApprox(slope, 1e-12))
          << "level " << level << (end == CurveEnd::kFirst ? ", first" : ", last")
          << " end: " << *velocity;
    }
  }
  EXPECT_EQ(*EndVelocity(ramp.topRows(1), {.level = 2.0}, CurveEnd::kLast),
            Eigen::RowVector2d::Zero());
  EXPECT_THAT(MessageOf(EndVelocity(ramp, {.level = -1.0}, CurveEnd::kLast).status()),
              HasSubstr("level"));
  // Through FillGap: two pieces of one line, smoothed, leave the gap on the line.
  const RowMatrixXd before = ramp.topRows(20);
  const RowMatrixXd after = ramp.bottomRows(10);
  const RowMatrixXd gap = *FillGap(before, after, {.frames = 10, .derivative_smoothing = 3.0});
  for (int k = 0; k < 10; ++k) EXPECT_TRUE(gap.row(k).isApprox(ramp.row(20 + k), 1e-12)) << k;
}

TEST(AlignedBlendTest, TheWarpMatchesPhasesThatAFrameForFrameBlendMixesUp) {
  // The second clip is the first played at half speed from where the overlap starts.
  const int overlap = 20;
  const RowMatrixXd a = Wave(60, 5);
  RowMatrixXd b(80, 5);
  for (int f = 0; f < 80; ++f) {
    const double source = 40 + 0.5 * f;  // a's frame 40 onwards, at half speed
    for (int d = 0; d < 5; ++d) {
      b(f, d) = (1.0 + d) * std::sin(0.07 * (d + 1) * source + d) + 0.5 * d;
    }
  }
  const absl::StatusOr<AlignedBlend> aligned = PlanAlignedBlend(a, b, {.overlap_frames = overlap});
  ASSERT_TRUE(aligned.ok()) << aligned.status();
  const absl::StatusOr<AlignedBlend> plain =
      PlanAlignedBlend(a, b, {.overlap_frames = overlap, .align = false});
  ASSERT_TRUE(plain.ok());
  EXPECT_LT(aligned->warp_score, 0.2 * plain->warp_score);

  // The plan: a's frames up to the overlap, a ramp across it, then the rest of b.
  const std::vector<BlendFrame>& frames = aligned->frames;
  for (int f = 0; f < 40; ++f) EXPECT_EQ(frames[f].a, f);
  int previous_b = -1;
  for (int i = 0; i < overlap; ++i) {
    const BlendFrame& frame = frames[40 + i];
    EXPECT_EQ(frame.a, 40 + i);
    EXPECT_GT(frame.weight_b, 0.0);
    EXPECT_LT(frame.weight_b, 1.0);
    EXPECT_GE(frame.b, previous_b);
    previous_b = frame.b;
    // Half speed: the second clip advances about two frames per frame of the first.
    EXPECT_NEAR(frame.b, 2 * i, 2);
  }
  EXPECT_EQ(frames.back().b, 79);
  EXPECT_EQ(frames.size(), 60 + (79 - static_cast<size_t>(previous_b)));
  // Mixed curves stay on the motion: the two clips agree where the warp matched them.
  const RowMatrixXd mixed = MixCurves(frames, a, b);
  for (int i = 0; i < overlap; ++i) {
    EXPECT_LT((mixed.row(40 + i) - a.row(40 + i)).norm(), 0.2) << "overlap frame " << i;
  }

  EXPECT_THAT(MessageOf(PlanAlignedBlend(a, b, {.overlap_frames = 61}).status()),
              HasSubstr("overlap_frames"));
  EXPECT_THAT(MessageOf(PlanAlignedBlend(a, b.topRows(5), {.overlap_frames = 20}).status()),
              HasSubstr("too short"));
  EXPECT_THAT(MessageOf(PlanAlignedBlend(a, b, {.warp = {.slope_limit = 9}}).status()),
              HasSubstr("warp.slope_limit"));
  EXPECT_THAT(MessageOf(PlanAlignedBlend(a, b, {.warp = {.dims = 6}}).status()),
              HasSubstr("warp.dims"));
}

}  // namespace
}  // namespace motiondb
