#include "core/search/warp_refinement.h"

#include <gtest/gtest.h>

#include "tests/search_test_data.h"

namespace motiondb {
namespace {

// A candidate matching query frame i to clip frame first + i, with its score.
SearchResult DiagonalCandidate(const RowMatrixXf& query, const RowMatrixXf& clip, int64_t first,
                               int anchor) {
  SearchResult candidate;
  candidate.path.resize(query.rows());
  for (int64_t i = 0; i < query.rows(); ++i) candidate.path[i] = first + i;
  candidate.first_frame = first;
  candidate.last_frame = first + query.rows() - 1;
  candidate.score = testing::MeanPathDistance(query, clip, candidate.path, query.cols());
  candidate.seed_frame = candidate.path[anchor];
  return candidate;
}

// A candidate that found the right motion 40 frames late (one frame per query frame): refinement
// must move it onto the planted copy, at the coarse-to-fine rates (120 Hz: a 30 Hz pass, then a
// full-rate one) and at 30 Hz (full rate only), both further than one band reaches.
TEST(RefineCandidate, MovesALateCandidateOntoTheMatch) {
  for (const double rate : {120.0, 30.0}) {
    SCOPED_TRACE(rate);
    const RowMatrixXf query = testing::Pattern(200, 5);
    RowMatrixXf clip = testing::SmoothNoise(1200, 5, 21);
    testing::Plant(clip, query, 400);
    SearchResult candidate = DiagonalCandidate(query, clip, 440, 100);
    const double before = candidate.score;
    BandWorkspace workspace;
    RefineCandidate(CoordinateView::Of(query), CoordinateView::Of(clip), 100, rate, {2, 5},
                    workspace, candidate);
    EXPECT_LT(candidate.score, 1e-6) << "from " << before;
    EXPECT_EQ(candidate.first_frame, 400);
    EXPECT_EQ(candidate.last_frame, 599);
    EXPECT_EQ(candidate.seed_frame, 500);
    EXPECT_NEAR(testing::MeanPathDistance(query, clip, candidate.path, 5), candidate.score, 1e-6);
  }
}

TEST(RefineCandidate, KeepsACandidateNothingNearBeats) {
  const RowMatrixXf query = testing::Pattern(60, 5);
  RowMatrixXf clip = testing::SmoothNoise(600, 5, 22);
  testing::Plant(clip, query, 200);
  SearchResult candidate = DiagonalCandidate(query, clip, 200, 30);
  ASSERT_EQ(candidate.score, 0);
  BandWorkspace workspace;
  RefineCandidate(CoordinateView::Of(query), CoordinateView::Of(clip), 30, 120.0, {2, 5}, workspace,
                  candidate);
  EXPECT_EQ(candidate.score, 0);
  EXPECT_EQ(candidate.first_frame, 200);
  EXPECT_EQ(candidate.seed_frame, 230);
}

}  // namespace
}  // namespace motiondb
