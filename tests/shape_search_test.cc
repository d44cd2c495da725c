// The search from the query's whole shape (SeedSelection::kShapeWindows) against brute force on
// small synthetic libraries: time-scaled copies found first, the exact search's results where
// the candidate ranges cover the library, the filters and the excluded range, bad parameters.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "tests/search_test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

constexpr int kDims = 12;
constexpr double kRate = 30.0;

// `rows` resampled to `frames` frames, linearly: the same motion performed faster or slower.
RowMatrixXf Resampled(const RowMatrixXf& rows, int frames) {
  RowMatrixXf out(frames, rows.cols());
  for (int i = 0; i < frames; ++i) {
    const double at = static_cast<double>(rows.rows() - 1) * i / (frames - 1);
    const auto below = static_cast<Eigen::Index>(at);
    const Eigen::Index above = std::min<Eigen::Index>(rows.rows() - 1, below + 1);
    const float w = static_cast<float>(at - static_cast<double>(below));
    out.row(i) = (1 - w) * rows.row(below) + w * rows.row(above);
  }
  return out;
}

SearchParams ShapeParams() {
  SearchParams params;
  params.seed_selection = SeedSelection::kShapeWindows;
  return params;
}

std::unique_ptr<LibraryIndex> NoiseLibrary(int clips, int64_t frames, uint32_t seed) {
  std::vector<LibraryClip> library;
  for (int c = 0; c < clips; ++c) {
    library.push_back({100 + c,
                       "clip" + std::to_string(c),
                       {c % 2 == 0 ? "even" : "odd"},
                       testing::SmoothNoise(frames, kDims, seed + c)});
  }
  return *LibraryIndex::Build(std::move(library), kRate, {});
}

// Most of the range first..last of clip `clip` covered by the result.
bool Covers(const SearchResult& r, int clip, int64_t first, int64_t last) {
  const int64_t overlap = std::min(r.last_frame, last) - std::max(r.first_frame, first) + 1;
  return r.clip_index == clip && overlap > 0.7 * static_cast<double>(last - first + 1);
}

TEST(ShapeSearch, FindsTimeScaledCopiesOfALibraryRangeFirst) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary(8, 1500, 40);
  for (const auto& [clip, first] : {std::pair{2, int64_t{300}}, std::pair{5, int64_t{1100}}}) {
    const int64_t frames = 60;
    const RowMatrixXf range = library->CopyClipCoordinates(clip).middleRows(first, frames);
    for (const double scale : {0.7, 1.0, 1.4}) {
      SCOPED_TRACE(::testing::Message() << "clip " << clip << " x" << scale);
      const RowMatrixXf query =
          Resampled(range, static_cast<int>(std::lround(scale * static_cast<double>(frames))));
      const absl::StatusOr<SearchResponse> found =
          Search(*library, CoordinateView::Of(query), ShapeParams());
      ASSERT_TRUE(found.ok()) << found.status();
      ASSERT_FALSE(found->results.empty());
      EXPECT_TRUE(Covers(found->results[0], clip, first, first + frames - 1))
          << "first: clip " << found->results[0].clip_index << " frames "
          << found->results[0].first_frame << ".." << found->results[0].last_frame;
      EXPECT_GT(found->stats.seeds, 0);
      EXPECT_GT(found->stats.clusters, 0);
    }
  }
}

// Queries of several lengths and slope limits on a small library, with windows enough that the
// ranges are its whole clips: `check`(library, query, params) for each.
void ForEachCoveringQuery(
    const std::function<void(const LibraryIndex&, const RowMatrixXf&, SearchParams)>& check) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary(3, 240, 70);
  int trial = 0;
  for (const int frames : {12, 30, 55, 100}) {
    for (const int slope : {2, 3}) {
      SCOPED_TRACE(::testing::Message() << frames << " frames, slope " << slope);
      const RowMatrixXf query = testing::SmoothNoise(frames, kDims, 500 + trial++);
      SearchParams params = ShapeParams();
      params.shape_windows = 10'000;
      params.slope_limit = slope;
      params.max_results = 8;
      params.return_path = trial % 2 == 0;
      check(*library, query, params);
    }
  }
}

// The re-ranking at the full rate (no refinement) is the exact search's scan over the ranges:
// where they cover the library, the same results.
TEST(ShapeSearch, EqualsTheExactSearchWhenTheCandidatesCoverASmallLibrary) {
  ForEachCoveringQuery([](const LibraryIndex& library, const RowMatrixXf& query,
                          SearchParams params) {
    params.refine = false;
    const absl::StatusOr<SearchResponse> shape = Search(library, CoordinateView::Of(query), params);
    const absl::StatusOr<SearchResponse> exact =
        ExactSearch(library, CoordinateView::Of(query), params);
    ASSERT_TRUE(shape.ok()) << shape.status();
    ASSERT_TRUE(exact.ok()) << exact.status();
    ASSERT_EQ(shape->results.size(), exact->results.size());
    for (size_t i = 0; i < exact->results.size(); ++i) {
      SCOPED_TRACE(i);
      EXPECT_EQ(shape->results[i].clip_id, exact->results[i].clip_id);
      EXPECT_EQ(shape->results[i].first_frame, exact->results[i].first_frame);
      EXPECT_EQ(shape->results[i].last_frame, exact->results[i].last_frame);
      EXPECT_NEAR(shape->results[i].score, exact->results[i].score, 1e-5);
      EXPECT_EQ(shape->results[i].path, exact->results[i].path);
    }
  });
}

// The same libraries re-ranked at 15 Hz (the default), the best coarse warps settled at 30 Hz
// in a band around their paths: every result a true warp, the exact search's best found, and
// most of its others overlapped by a result (what recall@10 counts).
TEST(ShapeSearch, SettlesTheCoarseReRankingNearTheExactSearchsResults) {
  ForEachCoveringQuery([](const LibraryIndex& library, const RowMatrixXf& query,
                          SearchParams params) {
    params.return_path = true;
    const SearchResponse shape = *Search(library, CoordinateView::Of(query), params);
    const SearchResponse exact = *ExactSearch(library, CoordinateView::Of(query), params);
    ASSERT_FALSE(shape.results.empty());
    ASSERT_FALSE(exact.results.empty());
    EXPECT_EQ(shape.results[0].clip_id, exact.results[0].clip_id);
    EXPECT_NEAR(shape.results[0].score, exact.results[0].score, 1e-5);
    int found = 0;
    for (const SearchResult& e : exact.results) {
      found += std::any_of(shape.results.begin(), shape.results.end(), [&](const SearchResult& r) {
        return Overlaps(e, r, 0.5) || Overlaps(r, e, 0.5);
      });
    }
    EXPECT_GE(found, static_cast<int>(exact.results.size()) - 2);
    for (const SearchResult& r : shape.results) {
      EXPECT_EQ(r.path.front(), r.first_frame);
      EXPECT_EQ(r.path.back(), r.last_frame);
      const RowMatrixXf clip = library.CopyClipCoordinates(r.clip_index);
      EXPECT_NEAR(testing::MeanPathDistance(query, clip, r.path, params.dtw_dims), r.score,
                  1e-4 * (1 + r.score));
    }
  });
}

// Fewer windows than cover the library: the results are still true warps of the model, ranked,
// each no better than the exact search's result of its rank.
TEST(ShapeSearch, RanksTrueWarpsNeverBetterThanTheExactSearch) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary(10, 600, 90);
  const RowMatrixXf query = library->CopyClipCoordinates(4).middleRows(200, 45);
  SearchParams params = ShapeParams();
  params.shape_windows = 20;
  params.shape_clips = 4;
  params.max_results = 6;
  params.return_path = true;
  const SearchResponse shape = *Search(*library, CoordinateView::Of(query), params);
  const SearchResponse exact = *ExactSearch(*library, CoordinateView::Of(query), params);
  ASSERT_FALSE(shape.results.empty());
  for (size_t i = 0; i < shape.results.size(); ++i) {
    const SearchResult& r = shape.results[i];
    if (i > 0) {
      EXPECT_LE(shape.results[i - 1].score, r.score);
    }
    if (i < exact.results.size()) {
      EXPECT_GE(r.score, exact.results[i].score - 1e-5);
    }
    ASSERT_EQ(r.path.size(), static_cast<size_t>(query.rows()));
    EXPECT_EQ(r.path.front(), r.first_frame);
    EXPECT_EQ(r.path.back(), r.last_frame);
    const RowMatrixXf clip = library->CopyClipCoordinates(r.clip_index);
    EXPECT_NEAR(testing::MeanPathDistance(query, clip, r.path, params.dtw_dims), r.score,
                1e-4 * (1 + r.score));
  }
  EXPECT_EQ(shape.results[0].clip_id, 104);
  EXPECT_NEAR(shape.results[0].score, 0.0, 1e-6);
}

TEST(ShapeSearch, KeepsToTheFiltersAndLeavesOutTheExcludedRange) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary(6, 600, 20);
  const RowMatrixXf query = library->CopyClipCoordinates(2).middleRows(250, 50);
  SearchParams params = ShapeParams();
  params.max_results = 10;
  params.clip_ids = {101, 103};
  SearchResponse found = *Search(*library, CoordinateView::Of(query), params);
  ASSERT_FALSE(found.results.empty());
  for (const SearchResult& r : found.results) {
    EXPECT_TRUE(r.clip_id == 101 || r.clip_id == 103) << r.clip_id;
  }
  params.clip_ids.clear();
  params.tags = {"odd"};
  found = *Search(*library, CoordinateView::Of(query), params);
  ASSERT_FALSE(found.results.empty());
  for (const SearchResult& r : found.results) EXPECT_EQ(r.clip_id % 2, 1) << r.clip_id;
  params.tags.clear();
  // The query's own range: found first without the exclusion, never with it, and the results
  // still fill max_results.
  const auto own = [](const SearchResult& r) {
    return r.clip_id == 102 && r.first_frame <= 299 && r.last_frame >= 250;
  };
  found = *Search(*library, CoordinateView::Of(query), params);
  ASSERT_FALSE(found.results.empty());
  EXPECT_TRUE(own(found.results[0]));
  params.excluded = ExcludedRange{102, 250, 299};
  found = *Search(*library, CoordinateView::Of(query), params);
  EXPECT_EQ(found.results.size(), 10u);
  EXPECT_TRUE(std::none_of(found.results.begin(), found.results.end(), own));
}

TEST(ShapeSearch, RefusesBadParametersNamingThem) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary(2, 300, 5);
  const RowMatrixXf query = testing::SmoothNoise(40, kDims, 9);
  const auto refused = [&](auto change, const std::string& field) {
    SearchParams params = ShapeParams();
    change(params);
    const absl::Status status = Search(*library, CoordinateView::Of(query), params).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << field;
    EXPECT_THAT(std::string(status.message()), HasSubstr(field));
  };
  refused([](SearchParams& p) { p.shape_windows = 0; }, "shape_windows");
  refused([](SearchParams& p) { p.shape_windows = 100'001; }, "shape_windows");
  refused([](SearchParams& p) { p.shape_clips = 0; }, "shape_clips");
  refused([](SearchParams& p) { p.shape_lengths_either_side = -1; }, "shape_lengths_either_side");
  refused([](SearchParams& p) { p.shape_lengths_either_side = 9; }, "shape_lengths_either_side");
  EXPECT_STREQ(SeedSelectionName(SeedSelection::kShapeWindows), "shape_windows");
}

TEST(ShapeSearch, IndexesShortClipsWholeAndStatesItsMemory) {
  // The library's lengths at 30 Hz: 15 to 170 frames about sqrt(2) apart.
  std::vector<LibraryClip> clips;
  clips.push_back({1, "long", {}, testing::SmoothNoise(900, kDims, 1)});
  clips.push_back({2, "short", {}, testing::SmoothNoise(40, kDims, 2)});
  const std::unique_ptr<LibraryIndex> library = *LibraryIndex::Build(std::move(clips), kRate, {});
  EXPECT_THAT(library->shape_lengths(), ::testing::ElementsAre(15, 21, 30, 42, 60, 85, 120, 170));
  EXPECT_EQ(library->shape_bytes(), 0);  // built by the first search that asks
  // The short clip performed 1.4x as slowly: a query longer than the clip, found in it.
  const RowMatrixXf query = Resampled(library->CopyClipCoordinates(1), 56);
  const SearchResponse found = *Search(*library, CoordinateView::Of(query), ShapeParams());
  ASSERT_FALSE(found.results.empty());
  EXPECT_EQ(found.results[0].clip_id, 2);
  const std::vector<ShapeWindow> whole =
      library->NearestShapes(CoordinateView::Of(query), library->ShapeLengthNearest(56), 1, 0, {});
  ASSERT_EQ(whole.size(), 1u);
  EXPECT_EQ(whole[0].clip, 1);
  EXPECT_EQ(whole[0].first_frame, 0);
  EXPECT_EQ(whole[0].frames, 40);
  EXPECT_GT(library->shape_bytes(), 0);
}

}  // namespace
}  // namespace motiondb
