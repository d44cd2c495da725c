#include "core/search/warp_refinement.h"

#include <limits>

#include <gtest/gtest.h>

#include "tests/search_test_data.h"

namespace motiondb {
namespace {

constexpr double kNoBound = std::numeric_limits<double>::infinity();

// The first five columns of a view's rows.
RowMatrixXf CopyRows(CoordinateView view) {
  RowMatrixXf copy(view.rows, 5);
  for (int64_t r = 0; r < view.rows; ++r) {
    for (int k = 0; k < 5; ++k) copy(r, k) = view.row(r)[k];
  }
  return copy;
}

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
// must move it onto the planted copy, further than one band reaches: in one pass at one rate, and
// as the fast search does it, from a candidate found at a quarter of the rate (every fourth frame
// of query and clip) settled there, then at the full rate.
TEST(RefineCandidate, MovesALateCandidateOntoTheMatch) {
  for (const int factor : {4, 1}) {
    SCOPED_TRACE(factor);
    const RowMatrixXf query = testing::Pattern(200, 5);
    RowMatrixXf clip = testing::SmoothNoise(1200, 5, 21);
    testing::Plant(clip, query, 400);
    const CoordinateView coarse_query = CoarseView(CoordinateView::Of(query), factor);
    const CoordinateView coarse_clip = CoarseView(CoordinateView::Of(clip), factor);
    const RowMatrixXf q = CopyRows(coarse_query), c = CopyRows(coarse_clip);
    SearchResult candidate = DiagonalCandidate(q, c, 440 / factor, 100 / factor);
    const double before = candidate.score;
    BandWorkspace workspace;
    RefineCandidate(coarse_query, coarse_clip, 100 / factor, 120.0 / factor, {2, 5}, workspace,
                    candidate);
    EXPECT_LT(candidate.score, 1e-6) << "from " << before;
    if (factor > 1) {
      for (int64_t& frame : candidate.path) frame *= factor;  // in the clip's own frames
      ASSERT_TRUE(RefineFromCoarse(CoordinateView::Of(query), CoordinateView::Of(clip), 100, factor,
                                   {2, 5}, kNoBound, workspace, candidate));
    }
    EXPECT_LT(candidate.score, 1e-6);
    EXPECT_EQ(candidate.first_frame, 400);
    EXPECT_EQ(candidate.last_frame, 599);
    EXPECT_EQ(candidate.seed_frame, 500);
    EXPECT_NEAR(testing::MeanPathDistance(query, clip, candidate.path, 5), candidate.score, 1e-6);
  }
}

// From a coarse candidate some way off, the full-rate settling takes the best warp in its narrow
// band whatever the coarse score was: never one that the model forbids.
TEST(RefineFromCoarse, GivesAFullRateWarpOfTheModel) {
  const RowMatrixXf query = testing::Pattern(120, 5);
  RowMatrixXf clip = testing::SmoothNoise(900, 5, 23);
  testing::Plant(clip, query, 300);
  const RowMatrixXf q = CopyRows(CoarseView(CoordinateView::Of(query), 4));
  const RowMatrixXf c = CopyRows(CoarseView(CoordinateView::Of(clip), 4));
  SearchResult candidate = DiagonalCandidate(q, c, 77, 15);  // 8 full-rate frames late
  for (int64_t& frame : candidate.path) frame *= 4;          // in the clip's own frames
  BandWorkspace workspace;
  ASSERT_TRUE(RefineFromCoarse(CoordinateView::Of(query), CoordinateView::Of(clip), 60, 4, {2, 5},
                               kNoBound, workspace, candidate));
  ASSERT_EQ(candidate.path.size(), 120u);
  EXPECT_EQ(candidate.seed_frame, candidate.path[60]);
  for (size_t i = 1; i < candidate.path.size(); ++i) {
    EXPECT_GE(candidate.path[i] - candidate.path[i - 1], 0);
    EXPECT_LE(candidate.path[i] - candidate.path[i - 1], 2);
  }
  EXPECT_NEAR(testing::MeanPathDistance(query, clip, candidate.path, 5), candidate.score, 1e-6);
  EXPECT_LT(candidate.score, 0.05);
}

// A bound under the settled warp's score leaves the candidate as it was; one over it changes
// nothing.
TEST(RefineFromCoarse, GivesUpOnlyOverTheBound) {
  const RowMatrixXf query = testing::Pattern(120, 5);
  RowMatrixXf clip = testing::SmoothNoise(900, 5, 24);
  testing::Plant(clip, query, 300);
  for (int i = 0; i < 120; ++i)
    clip.row(300 + i) += testing::SmoothNoise(1, 5, 100 + i).row(0) * 0.1f;
  const RowMatrixXf q = CopyRows(CoarseView(CoordinateView::Of(query), 4));
  const RowMatrixXf c = CopyRows(CoarseView(CoordinateView::Of(clip), 4));
  SearchResult coarse = DiagonalCandidate(q, c, 75, 15);
  for (int64_t& frame : coarse.path) frame *= 4;
  BandWorkspace workspace;
  SearchResult settled = coarse;
  ASSERT_TRUE(RefineFromCoarse(CoordinateView::Of(query), CoordinateView::Of(clip), 60, 4, {2, 5},
                               kNoBound, workspace, settled));
  ASSERT_GT(settled.score, 0);
  SearchResult under = coarse;
  EXPECT_FALSE(RefineFromCoarse(CoordinateView::Of(query), CoordinateView::Of(clip), 60, 4, {2, 5},
                                settled.score * 0.99, workspace, under));
  EXPECT_EQ(under.score, coarse.score);
  EXPECT_EQ(under.path, coarse.path);
  SearchResult over = coarse;
  ASSERT_TRUE(RefineFromCoarse(CoordinateView::Of(query), CoordinateView::Of(clip), 60, 4, {2, 5},
                               settled.score * 1.01, workspace, over));
  EXPECT_EQ(over.score, settled.score);
  EXPECT_EQ(over.path, settled.path);
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
