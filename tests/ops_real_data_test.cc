// The operators on real capture (../shared/mocap/bandai2-normal; skipped when absent): pose
// detection of raise-up-both-hands from five clips' peak poses (thesis 3.4), MC-LERP against
// SLERP (4.1), smoothing of noisy clips (5.5.1) and Hermite gaps against linear ones (4.3).
// bench/ops_measurements prints the same figures in full
// (bench/notes/2026-12-05-curve-operators.md).
#include <random>

#include <gtest/gtest.h>

#include "core/ops/gap_fill.h"
#include "core/ops/interpolation.h"
#include "core/ops/wavelet_smoothing.h"
#include "testing/ops_evaluation.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

class OpsRealDataTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto dir = testing::MocapDir();
    if (!dir) return;
    absl::StatusOr<testing::LabelledMotions> loaded =
        testing::LoadLabelledMotions(*dir / "bandai2-normal", testing::ArmsSpace());
    ASSERT_TRUE(loaded.ok()) << loaded.status();
    library_ = new testing::LabelledMotions(*std::move(loaded));
  }
  static void TearDownTestSuite() {
    delete library_;
    library_ = nullptr;
  }
  void SetUp() override {
    if (!testing::MocapDir()) GTEST_SKIP() << "../shared/mocap is absent; skipped";
    // Present but not loaded: the suite's set-up failed above, and so does every test.
    ASSERT_NE(library_, nullptr) << "bandai2-normal did not load";
  }
  static testing::LabelledMotions* library_;
};

testing::LabelledMotions* OpsRealDataTest::library_ = nullptr;

TEST_F(OpsRealDataTest, RaiseUpBothHandsIsDetectedFromFiveClipsPeakPoses) {
  testing::DetectionEvaluationOptions options;
  options.model.dims = 6;
  options.model.components = 1;
  const absl::StatusOr<testing::DetectionEvaluation> evaluation =
      testing::EvaluatePoseDetection(*library_, options);
  ASSERT_TRUE(evaluation.ok()) << evaluation.status();
  // 74 clips of the label, 5 of them the examples: precision and recall count the other 69.
  EXPECT_EQ(evaluation->positives, 69);
  EXPECT_GE(evaluation->precision(), 0.9) << evaluation->fired << " fired";
  EXPECT_GE(evaluation->recall(), 0.9) << evaluation->true_positives << " found";
  // The arm-waving clips, which pass through raised arms, are what the threshold must tell apart.
  EXPECT_LE(evaluation->by_label.at("wave-both-hands").first, 3);
}

TEST_F(OpsRealDataTest, McLerpStaysCloseToSlerpBetweenRealPoses) {
  std::mt19937_64 generator(4);
  const int joints = library_->space->skeleton().joint_count();
  double midpoint = 0, apart = 0;
  constexpr int kPairs = 200;
  for (int n = 0; n < kPairs; ++n) {
    RowMatrixXd poses(2, library_->space->dims()), rotations(2, 4 * joints);
    for (int side = 0; side < 2; ++side) {
      const SpaceMotion& motion = library_->motions[generator() % library_->motions.size()];
      const Eigen::Index frame = static_cast<Eigen::Index>(generator() % motion.coordinates.rows());
      poses.row(side) = motion.coordinates.row(frame);
      rotations.row(side) = motion.rotations.row(frame);
    }
    const absl::StatusOr<Interpolation> result =
        InterpolatePoses(*library_->space, poses, rotations);
    ASSERT_TRUE(result.ok()) << result.status();
    midpoint += result->difference[5].mean_rad;
    AngleError between;
    AngleErrors(rotations.row(0), rotations.row(1), nullptr, &between);
    apart += between.mean_rad;
  }
  // 4.1: similar, "significant artifacts only when the target poses are very different".
  EXPECT_LT(midpoint / kPairs, 0.01 * apart / kPairs);
}

TEST_F(OpsRealDataTest, SmoothingANoisyClipBringsItCloserToTheOriginal) {
  std::mt19937_64 generator(5);
  double raw = 0, smoothed = 0;
  for (size_t i = 0; i < library_->motions.size(); i += 31) {
    const absl::StatusOr<SpaceMotion> noisy = EnterSpace(
        *library_->space, testing::WithRotationNoise(library_->clips[i], 0.05, generator));
    ASSERT_TRUE(noisy.ok());
    for (const double level : {0.0, 1.5}) {
      const absl::StatusOr<RowMatrixXd> curve = SmoothCurve(noisy->coordinates, {.level = level});
      ASSERT_TRUE(curve.ok());
      const absl::StatusOr<RowMatrixXd> rotations = library_->space->Reconstruct(*curve);
      ASSERT_TRUE(rotations.ok());
      AngleError error;
      AngleErrors(*rotations, library_->motions[i].rotations, nullptr, &error);
      (level == 0.0 ? raw : smoothed) += error.mean_rad;
    }
  }
  EXPECT_LT(smoothed, 0.8 * raw);
}

TEST_F(OpsRealDataTest, AHermiteGapKeepsTheClipsVelocitiesBetterThanALine) {
  const double rate = library_->space->sample_rate();
  double hermite = 0, line = 0;
  for (size_t i = 0; i < library_->motions.size(); i += 7) {
    const SpaceMotion& a = library_->motions[i];
    const SpaceMotion& b = library_->motions[(i + 200) % library_->motions.size()];
    for (const GapMethod method : {GapMethod::kHermite, GapMethod::kLinear}) {
      const absl::StatusOr<RowMatrixXd> gap =
          FillGap(a.coordinates, b.coordinates, {.frames = 15, .method = method});
      ASSERT_TRUE(gap.ok());
      RowMatrixXd curve(a.coordinates.rows() + 15 + b.coordinates.rows(), gap->cols());
      curve << a.coordinates, *gap, b.coordinates;
      const absl::StatusOr<RowMatrixXd> rotations = library_->space->Reconstruct(curve);
      ASSERT_TRUE(rotations.ok());
      const int seam = static_cast<int>(a.coordinates.rows()) - 1;
      const double jump = VelocityJump(*rotations, seam, rate).mean_rad +
                          VelocityJump(*rotations, seam + 16, rate).mean_rad;
      (method == GapMethod::kHermite ? hermite : line) += jump;
    }
  }
  EXPECT_LT(hermite, 0.5 * line);
}

}  // namespace
}  // namespace motiondb
