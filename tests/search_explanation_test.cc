// A hit's explanation (server/search_explanation.h): the distance along the path split by joint
// exactly as the weighted pose vectors differ, and the speeds of the path.
#include "server/search_explanation.h"

#include <cmath>
#include <numeric>

#include <gtest/gtest.h>

#include "core/space/search_coordinates.h"
#include "tests/synthetic_motion.h"

namespace motiondb::server {
namespace {

class SearchExplanationTest : public ::testing::Test {
 protected:
  SearchExplanationTest()
      : skeleton_(testing::HumanoidSkeleton(/*still_root=*/true)),
        a_(testing::SyntheticClip(skeleton_, {.frames = 90, .fps = 30, .seed = 1})),
        b_(testing::SyntheticClip(skeleton_, {.frames = 90, .fps = 30, .seed = 2})),
        space_(*MotionSpace::Build({{"a", a_, std::nullopt}, {"b", b_, std::nullopt}})),
        query_(*SearchCoordinates(space_, a_)),
        clip_(*SearchCoordinates(space_, b_)) {}

  std::shared_ptr<const Skeleton> skeleton_;
  Clip a_, b_;
  MotionSpace space_;
  RowMatrixXf query_, clip_;
};

TEST_F(SearchExplanationTest, SplitsTheDistanceAsTheWeightedPosesDiffer) {
  // Query rows 10..49 against clip rows 20..59, one to one.
  const CoordinateView query = CoordinateView::Of(query_).middle_rows(10, 40);
  std::vector<int64_t> path(40);
  std::iota(path.begin(), path.end(), 20);
  const absl::StatusOr<SearchExplanation> explained =
      ExplainHit(space_, query, CoordinateView::Of(clip_), path);
  ASSERT_TRUE(explained.ok()) << explained.status();

  // By hand: the weighted pose vectors' difference per joint, and the full-space distance.
  const RowMatrixXd poses_a = *space_.EncodeClip(a_);
  const RowMatrixXd poses_b = *space_.EncodeClip(b_);
  const Eigen::VectorXd weights = space_.pose_weights();
  const int joints = skeleton_->joint_count();
  std::vector<double> squared(joints + 2, 0.0);
  double total = 0, distance = 0;
  for (int i = 0; i < 40; ++i) {
    const Eigen::VectorXd d =
        (poses_a.row(10 + i) - poses_b.row(20 + i)).transpose().cwiseProduct(weights);
    for (int k = 0; k < d.size(); ++k) {
      squared[k < 3 * joints ? k / 3 : (k == 3 * joints ? joints : joints + 1)] += d[k] * d[k];
    }
    total += d.squaredNorm();
    distance += d.norm();
  }
  EXPECT_NEAR(explained->full_score, distance / 40, 1e-4 * distance / 40);
  ASSERT_EQ(explained->joints.size(), static_cast<size_t>(joints + 2));
  double shares = 0, parts = 0;
  for (size_t g = 0; g < explained->joints.size(); ++g) {
    const JointShare& joint = explained->joints[g];
    const int group = joint.name == "yaw rate"        ? joints
                      : joint.name == "root velocity" ? joints + 1
                                                      : skeleton_->FindJoint(joint.name);
    ASSERT_GE(group, 0) << joint.name;
    EXPECT_NEAR(joint.share, squared[group] / total, 1e-4) << joint.name;
    if (g > 0) {
      EXPECT_GE(explained->joints[g - 1].share, joint.share);
    }
    shares += joint.share;
    parts += joint.score;
  }
  EXPECT_NEAR(shares, 1.0, 1e-9);
  EXPECT_NEAR(parts, explained->full_score, 1e-9);
  EXPECT_DOUBLE_EQ(explained->mean_speed, 1.0);
  EXPECT_DOUBLE_EQ(explained->max_speed, 1.0);
}

// In a space with a learned metric (search coordinates = the plain ones x a transform that is not
// orthogonal), the explanation is of the space's own distance: the same as the plain space's.
TEST_F(SearchExplanationTest, ALearnedMetricIsTurnedBackIntoTheSpacesOwn) {
  RowMatrixXd transform = RowMatrixXd::Identity(space_.dims(), space_.dims());
  for (int d = 0; d < space_.dims(); ++d) {
    transform(d, d) = 0.5 + 0.1 * d;
    transform((d + 3) % space_.dims(), d) = 0.4;  // a row mixed into a column: not symmetric
  }
  const MotionSpace learned = *space_.WithSearchTransform(transform);
  const RowMatrixXf query = *SearchCoordinates(learned, a_);
  const RowMatrixXf clip = *SearchCoordinates(learned, b_);
  std::vector<int64_t> path(40);
  std::iota(path.begin(), path.end(), 20);
  const SearchExplanation plain = *ExplainHit(
      space_, CoordinateView::Of(query_).middle_rows(10, 40), CoordinateView::Of(clip_), path);
  const SearchExplanation turned_back = *ExplainHit(
      learned, CoordinateView::Of(query).middle_rows(10, 40), CoordinateView::Of(clip), path);
  EXPECT_NEAR(turned_back.full_score, plain.full_score, 1e-4 * plain.full_score);
  ASSERT_EQ(turned_back.joints.size(), plain.joints.size());
  for (size_t g = 0; g < plain.joints.size(); ++g) {
    EXPECT_EQ(turned_back.joints[g].name, plain.joints[g].name) << g;
    EXPECT_NEAR(turned_back.joints[g].share, plain.joints[g].share, 1e-4) << g;
  }
  // Coordinates cut short cannot be turned back.
  EXPECT_EQ(ExplainHit(learned, CoordinateView{query.data(), 5, 3}, CoordinateView::Of(clip),
                       {0, 1, 2, 3, 4})
                .status()
                .code(),
            absl::StatusCode::kInternal);
}

TEST_F(SearchExplanationTest, SpeedsFollowThePath) {
  // The first half at the query's speed, the second twice as fast.
  const CoordinateView query = CoordinateView::Of(query_).middle_rows(0, 21);
  std::vector<int64_t> path;
  for (int i = 0; i <= 10; ++i) path.push_back(i);
  for (int i = 1; i <= 10; ++i) path.push_back(10 + 2 * i);
  const absl::StatusOr<SearchExplanation> explained =
      ExplainHit(space_, query, CoordinateView::Of(clip_), path);
  ASSERT_TRUE(explained.ok()) << explained.status();
  EXPECT_DOUBLE_EQ(explained->mean_speed, 30.0 / 20.0);
  EXPECT_DOUBLE_EQ(explained->max_speed, 2.0);
  // A path that leaves the clip, or does not fit the query, is refused.
  path.back() = 90;
  EXPECT_FALSE(ExplainHit(space_, query, CoordinateView::Of(clip_), path).ok());
  path.pop_back();
  EXPECT_FALSE(ExplainHit(space_, query, CoordinateView::Of(clip_), path).ok());
}

}  // namespace
}  // namespace motiondb::server
