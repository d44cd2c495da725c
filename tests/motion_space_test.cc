// Motion Curve spaces (SPEC §2-3, thesis 3.2-3.3): construction, projection, reconstruction,
// metrics, facing invariance, weighting, the error report and bad input.
#include "core/space/motion_space.h"

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"
#include "core/motion/resample.h"
#include "core/space/heading.h"
#include "tests/clip_builder.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;

std::vector<TrainingClip> Whole(const std::vector<Clip>& clips) {
  std::vector<TrainingClip> ranges;
  for (const Clip& clip : clips) {
    ranges.push_back({absl::StrCat("clip", ranges.size()), clip, std::nullopt});
  }
  return ranges;
}

// The largest angle between the rotations of two blocks of the same shape.
double MaxAngle(const RowMatrixXd& a, const RowMatrixXd& b) {
  double worst = 0.0;
  for (Eigen::Index f = 0; f < a.rows(); ++f) {
    for (Eigen::Index j = 0; j < a.cols() / 4; ++j) {
      const auto p = a.block<1, 4>(f, 4 * j);
      const auto q = b.block<1, 4>(f, 4 * j);
      worst =
          std::max(worst, AngleBetween(Quat(p[0], p[1], p[2], p[3]), Quat(q[0], q[1], q[2], q[3])));
    }
  }
  return worst;
}

// The share of a dimension's squared loadings that falls on `joints`.
double LoadingShare(const MotionSpace& space, int dimension, const std::vector<int>& joints) {
  const auto column = space.data().basis.col(dimension);
  double share = 0.0;
  for (const int j : joints) share += column.segment<3>(3 * j).squaredNorm();
  return share / column.squaredNorm();
}

class MotionSpaceTest : public ::testing::Test {
 protected:
  MotionSpaceTest()
      : skeleton_(testing::HumanoidSkeleton(/*still_root=*/true)),
        training_(Whole({testing::SyntheticClip(skeleton_, {.turn_rate = 0.5, .seed = 1}),
                         testing::SyntheticClip(skeleton_, {.frames = 90, .seed = 2})})),
        space_(*MotionSpace::Build(training_)) {}

  std::shared_ptr<const Skeleton> skeleton_;
  std::vector<TrainingClip> training_;
  MotionSpace space_;
};

TEST_F(MotionSpaceTest, KeepsEveryDimensionInDecreasingVarianceOnAnOrthonormalBasis) {
  const int joints = skeleton_->joint_count();
  EXPECT_EQ(space_.dims(), 3 * joints + 3);  // + the yaw rate and the root velocity
  const SpaceData& data = space_.data();
  EXPECT_TRUE((data.basis.transpose() * data.basis).isIdentity(1e-10));
  for (int i = 1; i < space_.dims(); ++i) EXPECT_GE(data.eigenvalues[i - 1], data.eigenvalues[i]);
  const Eigen::VectorXd explained = space_.ExplainedVariance();
  EXPECT_NEAR(explained.sum(), 1.0, 1e-12);
  EXPECT_GT(explained[0], explained[5]);
  // The still root and the pelvis's placement are not part of the pose: the Root's numbers never
  // vary, so its references are the identity.
  EXPECT_TRUE(data.references.row(0).isApprox(Eigen::RowVector4d(1, 0, 0, 0)));
  EXPECT_EQ(data.sample_rate, 30.0);
  ASSERT_EQ(data.training.size(), 2u);
  EXPECT_EQ(data.training[1].source, "clip1");
  EXPECT_EQ(data.training[1].frames.last, 89);
}

TEST_F(MotionSpaceTest, TrainingPosesRoundTripExactlyWithAllDimensions) {
  for (const TrainingClip& range : training_) {
    const Clip sampled = *Resample(range.clip, 30.0);
    const PoseRotations pose = ComputePoseRotations(sampled, space_.data().pose);
    const RowMatrixXd coordinates = *space_.ProjectClip(range.clip);
    ASSERT_EQ(coordinates.rows(), sampled.frame_count());
    EXPECT_LT(MaxAngle(*space_.Reconstruct(coordinates), pose.rotations), 1e-6);
  }
  const std::vector<ReconstructionError> report = *space_.RepresentationalError(training_);
  ASSERT_FALSE(report.empty());
  EXPECT_EQ(report.back().dims, space_.dims());
  EXPECT_LT(report.back().max_rad, 1e-6);
  EXPECT_LT(report.back().mean_rad, 1e-8);
}

TEST_F(MotionSpaceTest, ErrorShrinksAsDimensionsGrow) {
  const Clip unseen = testing::SyntheticClip(skeleton_, {.turn_rate = -0.3, .seed = 7});
  for (const std::vector<TrainingClip>& clips : {training_, Whole({unseen})}) {
    const std::vector<ReconstructionError> report = *space_.RepresentationalError(clips);
    ASSERT_EQ(report.size(), 5u);
    const int expected_dims[] = {3, 5, 10, 20, space_.dims()};
    for (size_t i = 0; i < report.size(); ++i) {
      EXPECT_EQ(report[i].dims, expected_dims[i]);
      EXPECT_GE(report[i].max_rad, report[i].mean_rad);
      if (i > 0) {
        EXPECT_LT(report[i].mean_rad, report[i - 1].mean_rad) << report[i].dims;
      }
    }
    EXPECT_GT(report.front().mean_rad, 0.01);  // 3 dimensions cannot hold this motion
    EXPECT_LT(report.back().max_rad, 1e-6);    // a full basis holds any pose
  }
  // Levels are sorted, de-duplicated and capped.
  const std::vector<ReconstructionError> custom =
      *space_.RepresentationalError(training_, {20, 1, 20, 1000});
  ASSERT_EQ(custom.size(), 3u);
  EXPECT_EQ(custom[0].dims, 1);
  EXPECT_EQ(custom[1].dims, 20);
  EXPECT_EQ(custom[2].dims, space_.dims());
}

TEST_F(MotionSpaceTest, QuaternionSignDoesNotMatter) {
  const Clip& clip = training_[0].clip;
  RowMatrixXd flipped = clip.rotations();
  for (Eigen::Index f = 0; f < flipped.rows(); ++f) {
    for (int j = 0; j < skeleton_->joint_count(); ++j) {
      if ((f + j) % 2 == 0) flipped.block<1, 4>(f, 4 * j) *= -1.0;
    }
  }
  const Clip negated = *Clip::Create(skeleton_, clip.frame_time(), flipped, clip.positions());
  const RowMatrixXd a = *space_.ProjectClip(clip);
  const RowMatrixXd b = *space_.ProjectClip(negated);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-9);
}

TEST_F(MotionSpaceTest, TurningTheBodyLeavesTheProjectionUnchangedUnlessTheHeadingIsKept) {
  const Clip& clip = training_[0].clip;
  const Clip turned = testing::TurnedClip(clip, kPi / 2);
  // The same turn, applied to the still root instead of the pelvis.
  RowMatrixXd rotations = clip.rotations();
  const Quat turn(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY()));
  for (Eigen::Index f = 0; f < rotations.rows(); ++f) {
    const Quat root = turn * clip.rotation(static_cast<int>(f), 0);
    rotations.block<1, 4>(f, 0) << root.w(), root.x(), root.y(), root.z();
  }
  const Clip turned_root = *Clip::Create(skeleton_, clip.frame_time(), rotations, clip.positions());

  const RowMatrixXd original = *space_.ProjectClip(clip);
  EXPECT_LT((*space_.ProjectClip(turned) - original).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((*space_.ProjectClip(turned_root) - original).cwiseAbs().maxCoeff(), 1e-6);

  SpaceOptions keep;
  keep.pose.remove_heading = false;
  const MotionSpace kept = *MotionSpace::Build(training_, keep);
  EXPECT_EQ(kept.dims(), 3 * skeleton_->joint_count());
  EXPECT_GT((*kept.ProjectClip(turned) - *kept.ProjectClip(clip)).cwiseAbs().maxCoeff(), 0.1);
}

TEST_F(MotionSpaceTest, TheYawRateFollowsTheJointsAndSetsTurnsApart) {
  const Clip left = testing::SyntheticClip(skeleton_, {.turn_rate = 1.0, .seed = 3});
  const Clip right = testing::SyntheticClip(skeleton_, {.turn_rate = -1.0, .seed = 3});
  const RowMatrixXd poses_left = *space_.EncodeClip(left);
  const RowMatrixXd poses_right = *space_.EncodeClip(right);
  const int yaw = 3 * skeleton_->joint_count();
  // The pelvis also sways, alike in both: the turns differ by exactly 2 rad/s.
  EXPECT_LT((poses_left.col(yaw) - poses_right.col(yaw)).array().abs().maxCoeff() - 2.0, 1e-9);
  EXPECT_GT((poses_left.col(yaw) - poses_right.col(yaw)).minCoeff(), 2.0 - 1e-9);
  EXPECT_GT(poses_left.col(yaw).mean(), 0.5);
  EXPECT_LT(poses_right.col(yaw).mean(), -0.5);
  EXPECT_DOUBLE_EQ(space_.pose_weights()[yaw], SpaceOptions().yaw_rate_weight);
  EXPECT_EQ(space_.pose_weights().tail(2),
            Eigen::VectorXd::Constant(2, SpaceOptions().root_velocity_weight));
  // The yaw rate does not shape the body: same joints, opposite turns, same reconstruction.
  const RowMatrixXd a = *space_.Reconstruct(*space_.ProjectClip(left));
  const RowMatrixXd b = *space_.Reconstruct(*space_.ProjectClip(right));
  EXPECT_LT(MaxAngle(a, b), 1e-6);
  EXPECT_GT((*space_.ProjectClip(left) - *space_.ProjectClip(right)).rowwise().norm().mean(),
            1.5 * SpaceOptions().yaw_rate_weight);
}

TEST_F(MotionSpaceTest, HeavierLegsPullTheFirstComponentOntoTheLegs) {
  const std::vector<int> legs = testing::LegJoints(*skeleton_);
  SpaceOptions keep;  // the yaw rate would take its own share; leave it out of this comparison
  keep.pose.remove_heading = false;
  const MotionSpace plain = *MotionSpace::Build(training_, keep);
  SpaceOptions heavy = keep;
  for (const int j : legs) heavy.weights.overrides[skeleton_->joint(j).name] = 5.0;
  const MotionSpace legs_first = *MotionSpace::Build(training_, heavy);
  EXPECT_LT(LoadingShare(plain, 0, legs), 0.5);
  EXPECT_GT(LoadingShare(legs_first, 0, legs), 0.9);
}

TEST_F(MotionSpaceTest, ProjectionIsOneBatchedProduct) {
  const RowMatrixXd poses = *space_.EncodeClip(training_[0].clip);
  const RowMatrixXd all = *space_.Project(poses);
  ASSERT_EQ(all.cols(), space_.dims());
  // p = (v .* w - m) B, row by row.
  const SpaceData& data = space_.data();
  for (Eigen::Index f = 0; f < poses.rows(); f += 7) {
    const Eigen::RowVectorXd expected =
        (poses.row(f).cwiseProduct(space_.pose_weights().transpose()) - data.mean.transpose()) *
        data.basis;
    EXPECT_LT((all.row(f) - expected).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LT((*space_.Project(poses.row(f)) - expected).cwiseAbs().maxCoeff(), 1e-10);
  }
  EXPECT_LT((*space_.Project(poses, 3) - all.leftCols(3)).cwiseAbs().maxCoeff(), 1e-12);
  // Unprojection inverts it with all dimensions, and puts the rest at the mean otherwise.
  EXPECT_LT((*space_.Unproject(all) - poses).cwiseAbs().maxCoeff(), 1e-10);
  const RowMatrixXd origin = *space_.Unproject(RowMatrixXd::Zero(1, 0));
  EXPECT_TRUE(origin.row(0)
                  .cwiseProduct(space_.pose_weights().transpose())
                  .isApprox(data.mean.transpose(), 1e-12));
}

TEST_F(MotionSpaceTest, UnitMetricIsTheWeightedPoseDistance) {
  const RowMatrixXd poses = *space_.EncodeClip(training_[1].clip);
  const RowMatrixXd points = *space_.Project(poses);
  const Eigen::RowVectorXd delta = poses.row(10) - poses.row(40);
  const double weighted = delta.cwiseProduct(space_.pose_weights().transpose()).norm();
  EXPECT_NEAR(*space_.Distance(points.row(10), points.row(40)), weighted, 1e-10);
  EXPECT_EQ(*space_.MetricScales(4), Eigen::VectorXd::Ones(4));
  const double truncated = *space_.Distance(points.row(10).head(3), points.row(40).head(3));
  EXPECT_LE(truncated, weighted);
  EXPECT_NEAR(truncated, (points.row(10).head(3) - points.row(40).head(3)).norm(), 1e-12);
}

TEST_F(MotionSpaceTest, EigenvalueMetricScalesEachDimensionByItsEigenvalue) {
  SpaceOptions options;
  options.metric = SpaceMetric::kEigenvalueScaled;
  const MotionSpace scaled = *MotionSpace::Build(training_, options);
  const Eigen::VectorXd& eigenvalues = scaled.data().eigenvalues;
  EXPECT_EQ(*scaled.MetricScales(5), eigenvalues.head(5));
  EXPECT_EQ(MetricScales(SpaceMetric::kEigenvalueScaled, eigenvalues, 2), eigenvalues.head(2));
  EXPECT_EQ(MetricScales(SpaceMetric::kUnit, eigenvalues, 2), Eigen::VectorXd::Ones(2));
  Eigen::RowVectorXd p = Eigen::RowVectorXd::Zero(3);
  Eigen::RowVectorXd q(3);
  q << 1.0, 2.0, -3.0;
  const double expected =
      std::sqrt(std::pow(eigenvalues[0] * 1.0, 2) + std::pow(eigenvalues[1] * 2.0, 2) +
                std::pow(eigenvalues[2] * 3.0, 2));
  EXPECT_NEAR(*scaled.Distance(p, q), expected, 1e-15);
  EXPECT_NEAR(*space_.Distance(p, q), std::sqrt(14.0), 1e-12);
}

TEST_F(MotionSpaceTest, ClipsAreSampledAtTheSpaceRate) {
  // 120 frames at 60 fps span 119 / 60 s: 60 samples at 30 Hz.
  EXPECT_EQ(space_.ProjectClip(training_[0].clip, 3)->rows(), 60);
  SpaceOptions options;
  options.sample_rate = 15.0;
  const MotionSpace slow = *MotionSpace::Build(training_, options);
  EXPECT_EQ(slow.ProjectClip(training_[0].clip, 3)->rows(), 30);
  EXPECT_EQ(slow.sample_rate(), 15.0);
}

TEST_F(MotionSpaceTest, TrainingRangesUseOnlyTheirFrames) {
  std::vector<TrainingClip> ranges = training_;
  ranges[0].frames = FrameRange{10, 69};
  const MotionSpace space = *MotionSpace::Build(ranges);
  EXPECT_EQ(space.data().training[0].frames.first, 10);
  EXPECT_EQ(space.data().training[0].frames.last, 69);
  EXPECT_FALSE(space.data().mean.isApprox(space_.data().mean, 1e-6));
  EXPECT_LT(space.RepresentationalError(ranges)->back().max_rad, 1e-6);
}

TEST_F(MotionSpaceTest, CmuStyleRootPelvis) {
  const auto cmu = testing::HumanoidSkeleton(/*still_root=*/false);
  const std::vector<TrainingClip> training =
      Whole({testing::SyntheticClip(cmu, {.turn_rate = 0.8, .seed = 4})});
  const MotionSpace space = *MotionSpace::Build(training);
  const Clip& clip = training[0].clip;
  EXPECT_LT((*space.ProjectClip(testing::TurnedClip(clip, -kPi / 2)) - *space.ProjectClip(clip))
                .cwiseAbs()
                .maxCoeff(),
            1e-6);
  EXPECT_LT(space.RepresentationalError(training)->back().max_rad, 1e-6);
}

TEST_F(MotionSpaceTest, RejectsBadTrainingAndOptions) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto fails = [&](const std::vector<TrainingClip>& training, const SpaceOptions& options,
                         const std::string& message) {
    const absl::StatusOr<MotionSpace> space = MotionSpace::Build(training, options);
    ASSERT_FALSE(space.ok()) << message;
    EXPECT_EQ(space.status().code(), absl::StatusCode::kInvalidArgument) << space.status();
    EXPECT_THAT(space.status().message(), HasSubstr(message));
  };
  fails(std::vector<TrainingClip>{}, {}, "needs training clips");
  for (const double rate : {0.0, -30.0, nan, 1e6, kMaxSpaceRate + 1}) {
    fails(training_, {.sample_rate = rate}, "sample rate");
  }
  for (const double weight : {0.0, -0.5, nan}) {
    fails(training_, {.yaw_rate_weight = weight}, "yaw-rate weight");
    fails(training_, {.root_velocity_weight = weight}, "root-velocity weight");
  }
  // Without the root velocity its weight is not used.
  EXPECT_TRUE(
      MotionSpace::Build(training_, {.pose = {.root_velocity = false}, .root_velocity_weight = -1})
          .ok());
  fails(training_, {.pose = {.yaw_rate_window = 0}}, "yaw-rate window");
  fails(training_, {.weights = {.overrides = {{"Tail", 1.0}}}}, "unknown joint 'Tail'");
  fails(training_, {.weights = {.overrides = {{"Hips", nan}}}}, "'Hips'");
  fails(training_, {.weights = {.overrides = {{"Hips", -1.0}}}}, "'Hips'");

  std::vector<TrainingClip> mixed = training_;
  mixed.push_back({"other.bvh", testing::SyntheticClip(testing::HumanoidSkeleton(false)), {}});
  fails(mixed, {}, "other.bvh: skeleton differs");

  std::vector<TrainingClip> out_of_range = training_;
  out_of_range[1].frames = FrameRange{50, 500};
  const absl::StatusOr<MotionSpace> space = MotionSpace::Build(out_of_range);
  ASSERT_FALSE(space.ok());
  EXPECT_THAT(space.status().message(), HasSubstr("clip1: frame range 50-500"));

  const Clip empty =
      *Clip::Create(skeleton_, 1.0 / 30, RowMatrixXd(0, 4 * skeleton_->joint_count()),
                    RowMatrixXd(0, 3 * skeleton_->position_joint_count()));
  fails(Whole({empty}), {}, "clip0: the clip has no frames");

  const Clip still = testing::MakeClip(
      skeleton_, 10, 1.0 / 30, [](int, int) { return Quat::Identity(); },
      [](int, int) { return Eigen::Vector3d::Zero(); });
  fails(Whole({still}), {}, "do not vary");
}

TEST_F(MotionSpaceTest, RejectsBadBlocksAndClips) {
  const RowMatrixXd poses = *space_.EncodeClip(training_[0].clip);
  EXPECT_THAT(space_.Project(poses.leftCols(10)).status().message(), HasSubstr("expects"));
  EXPECT_FALSE(space_.Project(poses, space_.dims() + 1).ok());
  EXPECT_FALSE(space_.Project(poses, -2).ok());
  EXPECT_FALSE(space_.Unproject(RowMatrixXd::Zero(2, space_.dims() + 1)).ok());
  EXPECT_FALSE(space_.Reconstruct(RowMatrixXd::Zero(2, space_.dims() + 1)).ok());
  EXPECT_FALSE(space_.MetricScales(space_.dims() + 1).ok());
  EXPECT_FALSE(space_.Distance(Eigen::RowVectorXd::Zero(3), Eigen::RowVectorXd::Zero(4)).ok());
  EXPECT_FALSE(space_.RepresentationalError(training_, {0}).ok());
  EXPECT_FALSE(space_.RepresentationalError(std::vector<TrainingClip>{}).ok());
  const Clip other = testing::SyntheticClip(testing::HumanoidSkeleton(false));
  EXPECT_THAT(space_.ProjectClip(other).status().message(), HasSubstr("skeleton differs"));
  EXPECT_THAT(space_.RepresentationalError(Whole({other})).status().message(),
              HasSubstr("clip0: skeleton differs"));
}

TEST_F(MotionSpaceTest, AFetchedSetIsReadAClipAtATimeAPassAtATime) {
  std::vector<size_t> fetched;
  const TrainingSet set{training_.size(), [&](size_t i) -> absl::StatusOr<TrainingClip> {
                          fetched.push_back(i);
                          return training_[i];
                        }};
  const MotionSpace space = *MotionSpace::Build(set);
  // Two passes, in order: the mean orientations, then the basis.
  EXPECT_THAT(fetched, ElementsAre(0, 0, 1, 0, 1));  // the first fetch finds the skeleton
  EXPECT_EQ(space.data().training.size(), training_.size());
  EXPECT_TRUE(space.data().mean.isApprox(space_.data().mean, 1e-12));
  EXPECT_TRUE(space.data().eigenvalues.isApprox(space_.data().eigenvalues, 1e-12));

  // The moments match the textbook covariance of all the weighted poses at once.
  RowMatrixXd weighted(0, space.dims());
  for (const TrainingClip& clip : training_) {
    const RowMatrixXd poses = *space.EncodeClip(clip.clip);
    weighted.conservativeResize(weighted.rows() + poses.rows(), Eigen::NoChange);
    weighted.bottomRows(poses.rows()) = poses * space.pose_weights().asDiagonal();
  }
  const Eigen::RowVectorXd mean = weighted.colwise().mean();
  EXPECT_LT((mean.transpose() - space.data().mean).cwiseAbs().maxCoeff(), 1e-12);
  const RowMatrixXd centred = weighted.rowwise() - mean;
  const Eigen::MatrixXd covariance =
      centred.transpose() * centred / static_cast<double>(weighted.rows());
  const Eigen::MatrixXd rebuilt =
      space.data().basis * space.data().eigenvalues.asDiagonal() * space.data().basis.transpose();
  EXPECT_LT((rebuilt - covariance).cwiseAbs().maxCoeff(), 1e-10);

  fetched.clear();
  ASSERT_TRUE(space.RepresentationalError(set).ok());
  EXPECT_THAT(fetched, ElementsAre(0, 1));

  const TrainingSet failing{2, [&](size_t i) -> absl::StatusOr<TrainingClip> {
                              if (i == 1) return absl::UnavailableError("disk gone");
                              return training_[i];
                            }};
  EXPECT_EQ(MotionSpace::Build(failing).status().code(), absl::StatusCode::kUnavailable);
}

TEST_F(MotionSpaceTest, BuildAndErrorReportStopWhenAsked) {
  int asked = 0;
  const auto stop_at_second = [&asked] { return ++asked == 2; };
  const absl::StatusOr<MotionSpace> space = MotionSpace::Build(training_, {}, stop_at_second);
  EXPECT_EQ(space.status().code(), absl::StatusCode::kCancelled) << space.status();
  asked = 0;
  EXPECT_EQ(
      space_.RepresentationalError(training_, kErrorReportDims, stop_at_second).status().code(),
      absl::StatusCode::kCancelled);
  const auto never = [] { return false; };
  EXPECT_TRUE(MotionSpace::Build(training_, {}, never).ok());
  EXPECT_TRUE(space_.RepresentationalError(training_, kErrorReportDims, never).ok());
}

TEST_F(MotionSpaceTest, FromDataChecksConsistency) {
  EXPECT_TRUE(MotionSpace::FromData(space_.data()).ok());
  {
    // Spaces stored when new ones could sample faster than kMaxSpaceRate still load.
    SpaceData fast = space_.data();
    fast.sample_rate = 4 * kMaxSpaceRate;
    EXPECT_TRUE(MotionSpace::FromData(std::move(fast)).ok());
  }
  const auto fails = [&](const std::function<void(SpaceData&)>& damage, const std::string& what) {
    SpaceData data = space_.data();
    damage(data);
    const absl::StatusOr<MotionSpace> space = MotionSpace::FromData(std::move(data));
    ASSERT_FALSE(space.ok()) << what;
    EXPECT_THAT(space.status().message(), HasSubstr(what));
  };
  fails([](SpaceData& d) { d.skeleton = nullptr; }, "no skeleton");
  fails([](SpaceData& d) { d.basis(0, 0) += 0.1; }, "not orthonormal");
  fails([](SpaceData& d) { d.joint_weights[2] = 0.0; }, "joint weights");
  fails([](SpaceData& d) { d.references(1, 0) = 2.0; }, "unit quaternions");
  fails([](SpaceData& d) { d.mean.conservativeResize(3); }, "mean is 3 x 1");
  fails([](SpaceData& d) { std::swap(d.eigenvalues[0], d.eigenvalues[1]); }, "decreasing");
  fails([](SpaceData& d) { d.pose.remove_heading = false; }, "mean is");
  fails([](SpaceData& d) { d.eigenvalues[3] = std::numeric_limits<double>::infinity(); }, "");
  fails([](SpaceData& d) { d.training.push_back({"x", {5, 2}}); }, "'x'");
}

// CMU 01_01 from Debian's assimp-testmodels: a real performance with turns and jumps.
TEST(MotionSpaceRealDataTest, Cmu0101) {
  const auto dir = testing::AssimpBvhDir();
  if (!dir) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  const absl::StatusOr<BvhReadResult> read = ReadBvhFile((*dir / "01_01.bvh").string());
  ASSERT_TRUE(read.ok()) << read.status();
  const std::vector<TrainingClip> training = {{"01_01", read->clip, std::nullopt}};
  const MotionSpace space = *MotionSpace::Build(training);
  EXPECT_EQ(space.dims(), 3 * 31 + 3);
  const std::vector<ReconstructionError> report = *space.RepresentationalError(training);
  for (size_t i = 1; i < report.size(); ++i) EXPECT_LT(report[i].mean_rad, report[i - 1].mean_rad);
  EXPECT_LT(report.back().max_rad, 1e-6);
  EXPECT_GT(space.ExplainedVariance().head(3).sum(), 0.8);

  const Clip turned = testing::TurnedClip(read->clip, kPi / 2);
  EXPECT_LT((*space.ProjectClip(turned) - *space.ProjectClip(read->clip)).cwiseAbs().maxCoeff(),
            1e-6);

  const Skeleton& skeleton = read->clip.skeleton();
  std::vector<int> legs;
  SpaceOptions heavy;
  for (const char* name : {"LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg", "RightLeg",
                           "RightFoot", "LHipJoint", "RHipJoint"}) {
    legs.push_back(skeleton.FindJoint(name));
    heavy.weights.overrides[name] = 5.0;
  }
  // The first joint component (the yaw rate takes dimension 0 in this clip of turns).
  const MotionSpace legs_first = *MotionSpace::Build(training, heavy);
  EXPECT_LT(LoadingShare(space, 1, legs), 0.4);
  EXPECT_GT(LoadingShare(legs_first, 0, legs), 0.8);
}

// Bandai: joint_Root is still and Hips carries the facing; turns show in the yaw rate.
TEST(MotionSpaceRealDataTest, BandaiTurnsAndRoundTrip) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  std::vector<TrainingClip> training;
  for (const char* name : {"walk", "walk-turn-left", "walk-turn-right", "raise-up-right-hand"}) {
    const std::string file = absl::StrCat("dataset-2_", name, "_normal_001.bvh");
    absl::StatusOr<BvhReadResult> read = ReadBvhFile((mocap / "bandai2-normal" / file).string());
    ASSERT_TRUE(read.ok()) << read.status();
    training.push_back({name, std::move(read->clip), std::nullopt});
  }
  const MotionSpace space = *MotionSpace::Build(training);
  EXPECT_EQ(space.skeleton().joint(FindPelvis(space.skeleton())).name, "Hips");
  EXPECT_EQ(space.dims(), 3 * 22 + 3);
  EXPECT_LT(space.RepresentationalError(training)->back().max_rad, 1e-6);
  const int yaw = 3 * 22;
  EXPECT_GT(space.EncodeClip(training[1].clip)->col(yaw).mean(), 0.3);   // left
  EXPECT_LT(space.EncodeClip(training[2].clip)->col(yaw).mean(), -0.3);  // right
  EXPECT_LT(std::abs(space.EncodeClip(training[0].clip)->col(yaw).mean()), 0.1);
}

}  // namespace
}  // namespace motiondb
