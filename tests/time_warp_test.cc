#include "core/search/warp/time_warp.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "tests/search_test_data.h"

namespace motiondb {
namespace {

// Every warp of the model, enumerated: w(anchor) = clip_anchor, steps of 0..s with at most s - 1
// pauses in a row (on each side of the anchor), inside the clip. Returns the best mean.
struct Best {
  double score = std::numeric_limits<double>::infinity();
  int64_t first = -1, last = -1;
};

void Enumerate(const RowMatrixXf& q, const RowMatrixXf& x, int s, int row, int direction,
               int64_t frame, int pauses, std::vector<int64_t>& path,
               std::vector<std::vector<int64_t>>& out) {
  path[row] = frame;
  const int next = row + direction;
  if (next < 0 || next >= q.rows()) {
    out.push_back(path);
    return;
  }
  for (int advance = 0; advance <= s; ++advance) {
    if (advance == 0 && pauses + 1 > s - 1) continue;
    const int64_t to = frame + direction * advance;
    if (to < 0 || to >= x.rows()) continue;
    Enumerate(q, x, s, next, direction, to, advance == 0 ? pauses + 1 : 0, path, out);
  }
}

Best BruteForce(const RowMatrixXf& q, const RowMatrixXf& x, int anchor, int64_t at, int s,
                int dims) {
  std::vector<int64_t> path(q.rows());
  std::vector<std::vector<int64_t>> forward, backward;
  Enumerate(q, x, s, anchor, +1, at, 0, path, forward);
  Enumerate(q, x, s, anchor, -1, at, 0, path, backward);
  Best best;
  for (const auto& f : forward) {
    for (const auto& b : backward) {
      std::vector<int64_t> whole(q.rows());
      for (int i = 0; i < q.rows(); ++i) whole[i] = i < anchor ? b[i] : f[i];
      const double score = testing::MeanPathDistance(q, x, whole, dims);
      if (score < best.score - 1e-9) best = {score, whole.front(), whole.back()};
    }
  }
  return best;
}

void ExpectValidPath(const Warp& warp, int anchor, int64_t at, int s, int64_t clip_rows) {
  ASSERT_FALSE(warp.path.empty());
  EXPECT_EQ(warp.path[anchor], at);
  EXPECT_EQ(warp.path.front(), warp.first);
  EXPECT_EQ(warp.path.back(), warp.last);
  int pauses = 0;
  for (size_t i = 1; i < warp.path.size(); ++i) {
    const int64_t advance = warp.path[i] - warp.path[i - 1];
    EXPECT_GE(advance, 0);
    EXPECT_LE(advance, s);
    pauses = advance == 0 ? pauses + 1 : 0;
    // The anchor splits the warp in two halves that are each constrained.
    if (static_cast<int>(i) != anchor + 1) {
      EXPECT_LE(pauses, 2 * (s - 1));
    }
    EXPECT_LT(warp.path[i], clip_rows);
  }
}

TEST(AnchoredWarp, MatchesExhaustiveEnumeration) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 40; ++trial) {
    const int s = 1 + trial % 3;
    const RowMatrixXf q = testing::SmoothNoise(6, 3, 100 + trial);
    const RowMatrixXf x = testing::SmoothNoise(14, 3, 200 + trial);
    const int anchor = static_cast<int>(rng() % q.rows());
    const int64_t at = static_cast<int64_t>(rng() % x.rows());
    const Best expected = BruteForce(q, x, anchor, at, s, 3);
    WarpWorkspace ws;
    const std::optional<Warp> warp =
        AnchoredWarp(CoordinateView::Of(q), CoordinateView::Of(x), anchor, at, {s, 3}, true, ws);
    if (!std::isfinite(expected.score)) {
      EXPECT_FALSE(warp.has_value()) << "trial " << trial;
      continue;
    }
    ASSERT_TRUE(warp.has_value()) << "trial " << trial;
    EXPECT_NEAR(warp->score, expected.score, 1e-5) << "trial " << trial;
    EXPECT_NEAR(testing::MeanPathDistance(q, x, warp->path, 3), warp->score, 1e-5);
    ExpectValidPath(*warp, anchor, at, s, x.rows());
  }
}

TEST(AnchoredWarp, FindsATimeStretchedCopyExactly) {
  // The clip holds the pattern performed 1.5x slower; every second query frame lands between
  // clip frames, so the best warp is near zero but the path must stretch.
  const RowMatrixXf query = testing::Pattern(40, 6);
  RowMatrixXf clip = testing::SmoothNoise(300, 6, 3);
  const RowMatrixXf slow = testing::Pattern(60, 6);
  testing::Plant(clip, slow, 100);
  const int anchor = 20;  // the pattern's peak, at 30 in the slow copy
  WarpWorkspace ws;
  const std::optional<Warp> warp = AnchoredWarp(CoordinateView::Of(query), CoordinateView::Of(clip),
                                                anchor, 130, {2, 6}, true, ws);
  ASSERT_TRUE(warp.has_value());
  EXPECT_NEAR(warp->first, 100, 1);
  EXPECT_NEAR(warp->last, 159, 1);
  // Sampling the slow copy at 2/3 of its frames leaves a small residual, far below noise (~1).
  EXPECT_LT(warp->score, 0.15);
  ExpectValidPath(*warp, anchor, 130, 2, clip.rows());
}

TEST(AnchoredWarp, SlopeLimitOneIsRigid) {
  const RowMatrixXf query = testing::Pattern(10, 2);
  const RowMatrixXf clip = testing::SmoothNoise(50, 2, 4);
  WarpWorkspace ws;
  const std::optional<Warp> warp =
      AnchoredWarp(CoordinateView::Of(query), CoordinateView::Of(clip), 3, 20, {1, 2}, true, ws);
  ASSERT_TRUE(warp.has_value());
  for (int i = 0; i < 10; ++i) EXPECT_EQ(warp->path[i], 17 + i);
}

TEST(AnchoredWarp, NoWarpWhenTheQueryCannotFitInsideTheClip) {
  const RowMatrixXf query = testing::Pattern(20, 2);
  const RowMatrixXf clip = testing::SmoothNoise(30, 2, 5);
  WarpWorkspace ws;
  // From the anchor the remaining 15 query frames need at least 8 clip frames at slope 2.
  EXPECT_FALSE(
      AnchoredWarp(CoordinateView::Of(query), CoordinateView::Of(clip), 4, 25, {2, 2}, false, ws)
          .has_value());
  EXPECT_FALSE(
      AnchoredWarp(CoordinateView::Of(query), CoordinateView::Of(clip), 15, 3, {2, 2}, false, ws)
          .has_value());
  EXPECT_TRUE(
      AnchoredWarp(CoordinateView::Of(query), CoordinateView::Of(clip), 10, 15, {2, 2}, false, ws)
          .has_value());
}

}  // namespace
}  // namespace motiondb
