// Pose detection (thesis 3.4, core/ops): a Mixture of Gaussians fitted by EM recovers a known
// mixture, scores by the closed form, is deterministic per seed, survives serialisation, and
// finds the intervals where a curve assumes the modelled pose.
#include <cmath>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "core/ops/pose_detection.h"
#include "core/ops/pose_model.h"
#include "core/ops/pose_model_serialization.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

struct Component {
  double weight;
  Eigen::Vector3d mean;
  Eigen::Matrix3d covariance;
};

// `count` samples of a known three-component mixture in three dimensions.
RowMatrixXd SampleMixture(const std::vector<Component>& mixture, int count, uint64_t seed) {
  std::mt19937_64 generator(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform;
  RowMatrixXd samples(count, 3);
  for (int n = 0; n < count; ++n) {
    double pick = uniform(generator);
    size_t c = 0;
    while (c + 1 < mixture.size() && pick >= mixture[c].weight) pick -= mixture[c++].weight;
    const Eigen::Matrix3d root = mixture[c].covariance.llt().matrixL();
    const Eigen::Vector3d z(normal(generator), normal(generator), normal(generator));
    samples.row(n) = (mixture[c].mean + root * z).transpose();
  }
  return samples;
}

std::vector<Component> KnownMixture() {
  Eigen::Matrix3d tilted;
  tilted << 0.5, 0.2, 0.0, 0.2, 0.3, 0.05, 0.0, 0.05, 0.2;
  return {{0.5, Eigen::Vector3d(0, 0, 0), 0.2 * Eigen::Matrix3d::Identity()},
          {0.3, Eigen::Vector3d(5, 5, 0), tilted},
          {0.2, Eigen::Vector3d(-4, 3, 6), 0.1 * Eigen::Matrix3d::Identity()}};
}

TEST(PoseModelTest, EmRecoversAKnownMixture) {
  const std::vector<Component> mixture = KnownMixture();
  const RowMatrixXd samples = SampleMixture(mixture, 6000, 11);
  const absl::StatusOr<PoseModel> model = FitPoseModel(samples, {.components = 3, .seed = 5});
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_NEAR(model->weights.sum(), 1.0, 1e-12);
  for (const Component& truth : mixture) {
    Eigen::Index nearest = 0;
    (model->means.rowwise() - truth.mean.transpose()).rowwise().norm().minCoeff(&nearest);
    EXPECT_LT((model->means.row(nearest).transpose() - truth.mean).norm(), 0.1);
    EXPECT_NEAR(model->weights[nearest], truth.weight, 0.03);
    EXPECT_LT((model->covariances[nearest] - truth.covariance).norm(), 0.1);
  }
  EXPECT_GT(model->iterations, 1);
}

TEST(PoseModelTest, ScoresByTheClosedFormAndIsDeterministicPerSeed) {
  const RowMatrixXd samples = SampleMixture(KnownMixture(), 500, 3);
  const absl::StatusOr<PoseModel> one = FitPoseModel(samples, {.components = 1});
  ASSERT_TRUE(one.ok());
  // A single Gaussian: the sample mean and covariance (plus the floor), and ln N by hand.
  const Eigen::RowVector3d mean = samples.colwise().mean();
  EXPECT_TRUE(one->means.row(0).isApprox(mean, 1e-9));
  const Eigen::Matrix3d& sigma = one->covariances[0];
  const Eigen::RowVector3d x(1.0, -2.0, 0.5);
  const Eigen::Vector3d d = (x - mean).transpose();
  const double expected = -0.5 * d.dot(sigma.inverse() * d) - 1.5 * std::log(2 * std::numbers::pi) -
                          0.5 * std::log(sigma.determinant());
  EXPECT_NEAR(PoseLogLikelihood(*one, x)[0], expected, 1e-9);

  const PoseModelOptions options{.components = 3, .seed = 9};
  const PoseModel a = *FitPoseModel(samples, options);
  const PoseModel b = *FitPoseModel(samples, options);
  EXPECT_EQ(a.means, b.means);
  EXPECT_EQ(a.weights, b.weights);
  EXPECT_EQ(SerializePoseModel(a), SerializePoseModel(b));
  // Diagonal and spherical models are what they say.
  const PoseModel diagonal =
      *FitPoseModel(samples, {.components = 2, .covariance = CovarianceType::kDiagonal});
  EXPECT_TRUE(diagonal.covariances[0].isDiagonal());
  const PoseModel spherical =
      *FitPoseModel(samples, {.components = 2, .covariance = CovarianceType::kSpherical});
  EXPECT_TRUE(spherical.covariances[1].isApprox(spherical.covariances[1](0, 0) *
                                                Eigen::Matrix3d::Identity()));
}

TEST(PoseModelTest, RoundTripsThroughItsStoredForm) {
  const RowMatrixXd samples = SampleMixture(KnownMixture(), 300, 4);
  const PoseModel model = *FitPoseModel(samples, {.components = 2, .dims = 2});
  const absl::StatusOr<PoseModel> parsed = ParsePoseModel(SerializePoseModel(model));
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_EQ(parsed->dims, 2);
  EXPECT_EQ(PoseLogLikelihood(*parsed, samples), PoseLogLikelihood(model, samples));
  EXPECT_EQ(parsed->threshold, model.threshold);
  EXPECT_FALSE(ParsePoseModel("{}").ok());
  EXPECT_FALSE(ParsePoseModel("not json").ok());
  std::string broken = SerializePoseModel(model);
  broken.replace(broken.find("\"weights\":["), 11, "\"weights\":[7,");
  EXPECT_FALSE(ParsePoseModel(broken).ok());
}

TEST(PoseModelTest, GroupsSetTheThresholdByModelsThatDidNotSeeThem) {
  // Two groups of one pose a little apart: each scored by a model of the other is less likely
  // than under the model of both, so the threshold admits a new instance that far off.
  std::mt19937_64 generator(3);
  std::normal_distribution<double> normal(0.0, 0.05);
  RowMatrixXd examples(100, 3);
  std::vector<int> groups;
  for (int n = 0; n < 100; ++n) {
    const double shift = n < 50 ? 0.0 : 0.3;
    examples.row(n) << shift + normal(generator), normal(generator), normal(generator);
    groups.push_back(n < 50 ? 0 : 1);
  }
  const PoseModel pooled = *FitPoseModel(examples, {.components = 1});
  const PoseModel held_out = *FitPoseModel(examples, {.components = 1}, groups);
  EXPECT_EQ(pooled.means, held_out.means);
  EXPECT_LT(held_out.threshold, pooled.threshold);
  // The threshold is the least likely example under the model of the other group.
  const PoseModel first = *FitPoseModel(examples.topRows(50), {.components = 1});
  const PoseModel second = *FitPoseModel(examples.bottomRows(50), {.components = 1});
  const double expected = std::min(PoseLogLikelihood(second, examples.topRows(50)).minCoeff(),
                                   PoseLogLikelihood(first, examples.bottomRows(50)).minCoeff());
  EXPECT_DOUBLE_EQ(held_out.threshold, expected);
  EXPECT_THAT(std::string(FitPoseModel(examples, {}, {0, 1}).status().message()),
              HasSubstr("groups"));
}

TEST(PoseModelTest, BadFitsAreRefusedNamingTheField) {
  const RowMatrixXd samples = SampleMixture(KnownMixture(), 10, 1);
  const auto message = [&](const PoseModelOptions& options) {
    return std::string(FitPoseModel(samples, options).status().message());
  };
  EXPECT_THAT(message({.components = 11}), HasSubstr("examples"));
  EXPECT_THAT(message({.components = 0}), HasSubstr("components"));
  EXPECT_THAT(message({.dims = 4}), HasSubstr("dims"));
  EXPECT_THAT(message({.tolerance = std::nan("")}), HasSubstr("tolerance"));
  EXPECT_THAT(message({.regularization = 0}), HasSubstr("regularization"));
  EXPECT_THAT(message({.threshold_quantile = 2}), HasSubstr("threshold_quantile"));
  EXPECT_THAT(std::string(FitPoseModel(RowMatrixXd(0, 3)).status().message()),
              HasSubstr("examples"));
  RowMatrixXd nan = samples;
  nan(3, 1) = std::nan("");
  EXPECT_THAT(std::string(FitPoseModel(nan).status().message()), HasSubstr("examples"));
  EXPECT_EQ(ParseCovarianceType("round").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(PoseDetectionTest, FindsTheIntervalsWhereTheCurveHoldsThePose) {
  // Examples of a pose near (1, 1, 1); a curve that holds it for frames 20-39 and 70-74.
  std::mt19937_64 generator(2);
  std::normal_distribution<double> normal(0.0, 0.05);
  RowMatrixXd examples(200, 4);
  for (int n = 0; n < 200; ++n) {
    examples.row(n) << 1 + normal(generator), 1 + normal(generator), 1 + normal(generator), 9;
  }
  const PoseModel model = *FitPoseModel(examples, {.components = 1});
  RowMatrixXd curve = RowMatrixXd::Constant(100, 4, -3.0);
  curve.middleRows(20, 20).setOnes();
  curve.middleRows(70, 5).setOnes();
  const absl::StatusOr<Detection> detection = DetectPose(model, curve);
  ASSERT_TRUE(detection.ok()) << detection.status();
  EXPECT_EQ(detection->threshold, model.threshold);
  ASSERT_EQ(detection->intervals.size(), 2u);
  EXPECT_EQ(detection->intervals[0].first, 20);
  EXPECT_EQ(detection->intervals[0].last, 39);
  EXPECT_EQ(detection->intervals[1].first, 70);
  EXPECT_EQ(detection->intervals[1].last, 74);
  EXPECT_GE(detection->intervals[0].peak_frame, 20);
  EXPECT_LE(detection->intervals[0].peak_frame, 39);
  EXPECT_EQ(detection->intervals[0].peak, detection->log_likelihood[20]);
  EXPECT_EQ(detection->log_likelihood.size(), 100);
  // With one group, the default threshold is the least likely example's own log-likelihood.
  const Eigen::VectorXd own = PoseLogLikelihood(model, examples);
  EXPECT_DOUBLE_EQ(own.minCoeff(), model.threshold);

  const absl::StatusOr<Detection> long_only = DetectPose(model, curve, {.min_frames = 6});
  ASSERT_EQ(long_only->intervals.size(), 1u);
  const absl::StatusOr<Detection> strict = DetectPose(model, curve, {.threshold = 1e9});
  EXPECT_TRUE(strict->intervals.empty());
  EXPECT_THAT(std::string(DetectPose(model, curve, {.threshold = std::nan("")}).status().message()),
              HasSubstr("threshold"));
  EXPECT_THAT(std::string(DetectPose(model, curve.leftCols(2)).status().message()),
              HasSubstr("curve"));
}

}  // namespace
}  // namespace motiondb
