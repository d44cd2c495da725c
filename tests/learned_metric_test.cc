// core/space/learned_metric.h: what a group changes is shrunk, the first dimensions carry the
// most variance, shrink 0 keeps the metric, and bad examples or options are refused.
#include "core/space/learned_metric.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "core/space/search_coordinates.h"
#include "tests/synthetic_motion.h"

namespace motiondb {
namespace {

// 30 frames of a motion in 3 dimensions: label A or B moves along dimension 0 (B one unit
// higher), the group offsets every frame by `group_offset` along dimension 1, and dimension 2
// holds a small wobble.
RowMatrixXf Curve(bool label_b, float group_offset, float phase) {
  RowMatrixXf curve(30, 3);
  for (int t = 0; t < 30; ++t) {
    curve(t, 0) = (label_b ? 1.0f : 0.0f) + 0.3f * std::sin(0.2f * t + phase);
    curve(t, 1) = group_offset + 0.05f * std::cos(0.3f * t);
    curve(t, 2) = 0.02f * std::sin(0.7f * t + 2 * phase);
  }
  return curve;
}

// The mean distance between the two curves' frames, after `transform`.
double MeanDistance(const RowMatrixXf& a, const RowMatrixXf& b, const Eigen::MatrixXd& transform) {
  const Eigen::MatrixXd difference = (a.cast<double>() - b.cast<double>()) * transform;
  return difference.rowwise().norm().mean();
}

struct Library {
  std::vector<RowMatrixXf> curves;
  std::vector<LabelledCurve> examples;
};

// Two groups two units apart, each with examples of A and B.
Library TwoGroups() {
  Library library;
  for (const float offset : {-1.0f, 1.0f}) {
    for (const bool label_b : {false, true}) {
      for (const float phase : {0.0f, 0.5f}) {
        library.curves.push_back(Curve(label_b, offset, phase + offset));
      }
    }
  }
  for (size_t i = 0; i < library.curves.size(); ++i) {
    library.examples.push_back({&library.curves[i], (i / 2) % 2 == 1 ? "B" : "A",
                                i < library.curves.size() / 2 ? "g1" : "g2"});
  }
  return library;
}

TEST(LearnedMetric, ShrinksWhatTheGroupsChange) {
  const Library library = TwoGroups();
  const RowMatrixXf& a1 = library.curves[0];  // A in g1
  const RowMatrixXf& b1 = library.curves[2];  // B in g1
  const RowMatrixXf& a2 = library.curves[4];  // A in g2
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(3, 3);
  // In the coordinates' own metric the group matters more than the label.
  ASSERT_LT(MeanDistance(a1, b1, identity), MeanDistance(a1, a2, identity));
  absl::StatusOr<Eigen::MatrixXd> transform = FitLearnedMetric(library.examples);
  ASSERT_TRUE(transform.ok()) << transform.status();
  ASSERT_EQ(transform->rows(), 3);
  ASSERT_EQ(transform->cols(), 3);
  // In the learned one the label does, by a margin (0.55 of it measured).
  EXPECT_LT(MeanDistance(a1, a2, *transform), 0.75 * MeanDistance(a1, b1, *transform));
  // Also when the 30-frame examples are aligned over every third frame only.
  const Eigen::MatrixXd sparse = *FitLearnedMetric(library.examples, {.max_frames = 10});
  EXPECT_LT(MeanDistance(a1, a2, sparse), 0.75 * MeanDistance(a1, b1, sparse));
  EXPECT_FALSE(sparse.isApprox(*transform, 1e-6));
}

TEST(LearnedMetric, FirstDimensionsCarryTheMostVarianceAndTheTotalIsKept) {
  const Library library = TwoGroups();
  const Eigen::MatrixXd transform = *FitLearnedMetric(library.examples);
  Eigen::MatrixXd frames(0, 3);
  for (const RowMatrixXf& curve : library.curves) {
    frames.conservativeResize(frames.rows() + curve.rows(), Eigen::NoChange);
    frames.bottomRows(curve.rows()) = curve.cast<double>();
  }
  const auto variances = [](const Eigen::MatrixXd& rows) {
    const Eigen::MatrixXd centred = rows.rowwise() - rows.colwise().mean();
    return Eigen::VectorXd(centred.colwise().squaredNorm() / static_cast<double>(rows.rows()));
  };
  const Eigen::VectorXd before = variances(frames);
  const Eigen::VectorXd after = variances(frames * transform);
  EXPECT_GE(after[0], after[1]);
  EXPECT_GE(after[1], after[2]);
  EXPECT_NEAR(after.sum(), before.sum(), 1e-9 * before.sum());
}

TEST(LearnedMetric, ShrinkZeroIsARotation) {
  const Library library = TwoGroups();
  const Eigen::MatrixXd transform = *FitLearnedMetric(library.examples, {.shrink = 0});
  EXPECT_TRUE((transform.transpose() * transform).isApprox(Eigen::MatrixXd::Identity(3, 3), 1e-9))
      << transform;
}

TEST(LearnedMetric, RefusesWhatItCannotFitOn) {
  Library library = TwoGroups();
  EXPECT_EQ(FitLearnedMetric(library.examples, {.shrink = 1}).status().message(),
            "shrink: 1 is outside [0, 1)");
  EXPECT_EQ(FitLearnedMetric(library.examples, {.shrink = -0.1}).status().message(),
            "shrink: -0.1 is outside [0, 1)");
  EXPECT_EQ(FitLearnedMetric(library.examples, {.partners = 0}).status().message(),
            "partners: 0 is below 1");
  EXPECT_EQ(FitLearnedMetric(library.examples, {.max_frames = 1}).status().message(),
            "max_frames: 1 is below 2");
  EXPECT_EQ(FitLearnedMetric({}).status().message(), "examples: none given");

  // One group only: nothing says what a group changes.
  const std::vector<LabelledCurve> one_group(library.examples.begin(),
                                             library.examples.begin() + 4);
  EXPECT_EQ(FitLearnedMetric(one_group).status().code(), absl::StatusCode::kFailedPrecondition);

  const RowMatrixXf narrow = RowMatrixXf::Zero(5, 2);
  std::vector<LabelledCurve> mixed = library.examples;
  mixed[3].coordinates = &narrow;
  EXPECT_EQ(FitLearnedMetric(mixed).status().message(),
            "examples[3]: 5 x 2 coordinates; every example needs frames of 3 dimensions");

  EXPECT_EQ(FitLearnedMetric(library.examples, {}, [] { return true; }).status().code(),
            absl::StatusCode::kCancelled);

  library.curves[5](7, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(FitLearnedMetric(library.examples).status().message(),
            "examples[5]: its coordinates hold a non-finite number");
}

// Every k-th frame, at most the number asked for, from the first.
TEST(LearnedMetric, AlignedFramesAreEveryKthAtMostTheNumberAsked) {
  RowMatrixXf rows(31, 2);
  for (int r = 0; r < 31; ++r) rows.row(r) << static_cast<float>(r), 0.0f;
  const RowMatrixXf every_fourth = AlignedFrames(rows, 10);
  ASSERT_EQ(every_fourth.rows(), 8);
  for (int r = 0; r < 8; ++r) EXPECT_EQ(every_fourth(r, 0), 4.0f * r);
  EXPECT_EQ(AlignedFrames(rows.topRows(30), 10).rows(), 10);
  EXPECT_EQ(AlignedFrames(rows, 300), rows);
}

// A space with a search transform gives search coordinates that are its plain ones times the
// transform, truncated after the product; its projections do not change.
TEST(LearnedMetric, SearchCoordinatesAreThePlainOnesTimesTheTransform) {
  const Clip clip = testing::SyntheticClip(testing::HumanoidSkeleton(/*still_root=*/true),
                                           {.frames = 40, .turn_rate = 0.3});
  const MotionSpace plain = *MotionSpace::Build({{"walk.bvh", clip, std::nullopt}});
  RowMatrixXd transform = RowMatrixXd::Identity(plain.dims(), plain.dims());
  transform(plain.dims() - 1, 0) = 2.0;  // the last dimension mixed into the first
  transform(1, 1) = 0.5;
  const MotionSpace learned = *plain.WithSearchTransform(transform);
  const RowMatrixXf before = *SearchCoordinates(plain, clip);
  const RowMatrixXf after = *SearchCoordinates(learned, clip);
  const RowMatrixXf expected = (before.cast<double>() * transform).cast<float>();
  ASSERT_EQ(after.rows(), expected.rows());
  EXPECT_TRUE(after.isApprox(expected, 1e-5f));
  const RowMatrixXf three = *SearchCoordinates(learned, clip, 3);
  EXPECT_EQ(three, after.leftCols(3));
  EXPECT_FALSE(SearchCoordinates(learned, clip, plain.dims() + 1).ok());
  EXPECT_EQ(*learned.ProjectClip(clip), *plain.ProjectClip(clip));
}

}  // namespace
}  // namespace motiondb
