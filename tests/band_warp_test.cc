#include "core/search/warp/band_warp.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "tests/search_test_data.h"

namespace motiondb {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Every path of the warp model from every start, each row within `radius` of `centre`, inside
// the clip: the best mean distance, by exhaustive enumeration.
void Enumerate(const RowMatrixXf& q, const RowMatrixXf& x, int s,
               const std::vector<int64_t>& centre, int radius, int row, int64_t frame, int pauses,
               double sum, double& best) {
  if (frame < 0 || frame >= x.rows() || std::abs(frame - centre[row]) > radius) return;
  sum += Distance(q.row(row).data(), x.row(frame).data(), q.cols());
  if (row + 1 == q.rows()) {
    best = std::min(best, sum / q.rows());
    return;
  }
  for (int advance = 0; advance <= s; ++advance) {
    if (advance == 0 && pauses + 1 > s - 1) continue;
    Enumerate(q, x, s, centre, radius, row + 1, frame + advance, advance == 0 ? pauses + 1 : 0, sum,
              best);
  }
}

double BruteForce(const RowMatrixXf& q, const RowMatrixXf& x, int s,
                  const std::vector<int64_t>& centre, int radius) {
  double best = kInfinity;
  for (int64_t start = 0; start < x.rows(); ++start) {
    Enumerate(q, x, s, centre, radius, 0, start, 0, 0.0, best);
  }
  return best;
}

// A random path of the model: steps of 1..s (no pauses, so it is valid for every s).
std::vector<int64_t> RandomCentre(int rows, int s, int64_t start, std::mt19937& rng) {
  std::vector<int64_t> centre(rows, start);
  for (int i = 1; i < rows; ++i) centre[i] = centre[i - 1] + 1 + static_cast<int>(rng() % s);
  return centre;
}

TEST(BandWarp, MatchesExhaustiveEnumerationInTheBand) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const int s = 1 + trial % 3;
    const int radius = trial % 4;
    const RowMatrixXf q = testing::SmoothNoise(6, 3, 300 + trial);
    const RowMatrixXf x = testing::SmoothNoise(24, 3, 400 + trial);
    const std::vector<int64_t> centre =
        RandomCentre(6, s, static_cast<int64_t>(rng() % 6), rng);  // may start at the clip's edge
    BandWorkspace ws;
    bool touches_edge = false;
    const Warp warp = *BandWarp(CoordinateView::Of(q), CoordinateView::Of(x), centre, radius,
                                {s, 3}, ws, &touches_edge);
    EXPECT_NEAR(warp.score, BruteForce(q, x, s, centre, radius), 1e-5) << "trial " << trial;
    EXPECT_LE(warp.score, testing::MeanPathDistance(q, x, centre, 3) + 1e-6) << "trial " << trial;
    // The path is one of the model's, in the band, and has the reported score.
    ASSERT_EQ(warp.path.size(), 6u);
    EXPECT_EQ(warp.path.front(), warp.first);
    EXPECT_EQ(warp.path.back(), warp.last);
    int pauses = 0;
    bool on_edge = false;
    for (int i = 0; i < 6; ++i) {
      EXPECT_LE(std::abs(warp.path[i] - centre[i]), radius);
      on_edge |= std::abs(warp.path[i] - centre[i]) == radius && warp.path[i] > 0 &&
                 warp.path[i] < x.rows() - 1;
      if (i == 0) continue;
      const int64_t advance = warp.path[i] - warp.path[i - 1];
      EXPECT_GE(advance, 0);
      EXPECT_LE(advance, s);
      pauses = advance == 0 ? pauses + 1 : 0;
      EXPECT_LE(pauses, s - 1);
    }
    EXPECT_EQ(touches_edge, on_edge) << "trial " << trial;
    EXPECT_NEAR(testing::MeanPathDistance(q, x, warp.path, 3), warp.score, 1e-5);
  }
}

TEST(BandWarp, AWideBandFindsTheBestWarpAnywhereInTheClip) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 12; ++trial) {
    const int s = 1 + trial % 3;
    const RowMatrixXf q = testing::SmoothNoise(5, 3, 500 + trial);
    const RowMatrixXf x = testing::SmoothNoise(16, 3, 600 + trial);
    const std::vector<int64_t> centre = RandomCentre(5, s, 4, rng);
    BandWorkspace ws;
    bool touches_edge = true;
    const Warp warp = *BandWarp(CoordinateView::Of(q), CoordinateView::Of(x), centre, 40, {s, 3},
                                ws, &touches_edge);
    EXPECT_NEAR(warp.score, BruteForce(q, x, s, std::vector<int64_t>(5, 0), 1000), 1e-5);
    EXPECT_FALSE(touches_edge);
  }
}

// Abandoning gives up exactly the warps that cost more than the bound, and changes nothing else.
TEST(BandWarp, AbandonsOnlyWarpsCostingMoreThanTheBound) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 40; ++trial) {
    const int s = 1 + trial % 3;
    const int radius = 1 + trial % 4;
    const RowMatrixXf q = testing::SmoothNoise(12, 3, 900 + trial);
    const RowMatrixXf x = testing::SmoothNoise(60, 3, 1000 + trial);
    const std::vector<int64_t> centre =
        RandomCentre(12, s, 2 + static_cast<int64_t>(rng() % 8), rng);
    BandWorkspace ws;
    bool touches_edge = false;
    const Warp full = *BandWarp(CoordinateView::Of(q), CoordinateView::Of(x), centre, radius,
                                {s, 3}, ws, &touches_edge);
    const bool full_touches_edge = touches_edge;
    const float cost = static_cast<float>(full.score * 12);
    EXPECT_FALSE(BandWarp(CoordinateView::Of(q), CoordinateView::Of(x), centre, radius, {s, 3}, ws,
                          &touches_edge, cost * 0.999f))
        << "trial " << trial;
    const std::optional<Warp> kept = BandWarp(CoordinateView::Of(q), CoordinateView::Of(x), centre,
                                              radius, {s, 3}, ws, &touches_edge, cost * 1.001f);
    ASSERT_TRUE(kept) << "trial " << trial;
    EXPECT_EQ(kept->score, full.score);
    EXPECT_EQ(kept->path, full.path);
    EXPECT_EQ(touches_edge, full_touches_edge);
  }
}

// A centre that pauses (as an upsampled coarse path does) moves the band by 0 frames on some
// rows: the band still holds the best warp inside it.
TEST(BandWarp, CentreWithPauses) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const int s = 2 + trial % 2;
    const RowMatrixXf q = testing::SmoothNoise(6, 3, 700 + trial);
    const RowMatrixXf x = testing::SmoothNoise(20, 3, 800 + trial);
    std::vector<int64_t> centre(6, 3);
    for (int i = 1; i < 6; ++i) centre[i] = centre[i - 1] + static_cast<int>(rng() % (s + 1));
    BandWorkspace ws;
    bool touches_edge = false;
    const Warp warp = *BandWarp(CoordinateView::Of(q), CoordinateView::Of(x), centre, 1 + trial % 3,
                                {s, 3}, ws, &touches_edge);
    EXPECT_NEAR(warp.score, BruteForce(q, x, s, centre, 1 + trial % 3), 1e-5) << trial;
  }
}

TEST(BandWarp, FollowsAShiftedCopy) {
  // The pattern sits 3 frames later than the centre path says: a band of radius 3 finds it.
  const RowMatrixXf query = testing::Pattern(30, 4);
  RowMatrixXf clip = testing::SmoothNoise(200, 4, 9);
  testing::Plant(clip, query, 53);
  std::vector<int64_t> centre(30);
  for (int i = 0; i < 30; ++i) centre[i] = 50 + i;
  BandWorkspace ws;
  bool touches_edge = false;
  Warp warp = *BandWarp(CoordinateView::Of(query), CoordinateView::Of(clip), centre, 3, {2, 4}, ws,
                        &touches_edge);
  EXPECT_NEAR(warp.score, 0.0, 1e-6);
  EXPECT_EQ(warp.first, 53);
  EXPECT_EQ(warp.last, 82);
  EXPECT_TRUE(touches_edge);
  // Radius 2 cannot reach it, and says so.
  warp = *BandWarp(CoordinateView::Of(query), CoordinateView::Of(clip), centre, 2, {2, 4}, ws,
                   &touches_edge);
  EXPECT_GT(warp.score, 0.0);
  EXPECT_TRUE(touches_edge);
}

}  // namespace
}  // namespace motiondb
