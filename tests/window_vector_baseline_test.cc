// The window-vector baseline of bench/ (issue 39) against brute force on a small synthetic
// library: its windows and their vectors, its top hits against a scan of the same window vectors
// (an index searched exhaustively enough, and under a filter), an exact copy of a window found
// first, FLANN's recall against the exact nearest windows, and the retrieval evaluation's
// figures for a baseline.
#include "bench/window_vector_baseline.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/exact_search.h"
#include "testing/retrieval_evaluation.h"
#include "tests/search_test_data.h"

namespace motiondb {
namespace {

using bench::WindowBaselineOptions;
using bench::WindowIndexKind;
using bench::WindowVectorBaseline;

constexpr int kDims = 12;  // more than the baseline's 10: only the first 10 count
constexpr double kRate = 30.0;

// Six clips of smooth noise at 30 Hz, one (index 2) shorter than the 1 s window; ids from
// `first_id`.
std::unique_ptr<LibraryIndex> NoiseLibrary(int64_t first_id = 100) {
  std::vector<LibraryClip> clips;
  const int64_t lengths[] = {400, 260, 20, 333, 500, 151};
  for (int c = 0; c < 6; ++c) {
    clips.push_back({first_id + c, "noise", {}, testing::SmoothNoise(lengths[c], kDims, 70 + c)});
  }
  auto library = LibraryIndex::Build(std::move(clips), kRate, {});
  EXPECT_TRUE(library.ok()) << library.status();
  return *std::move(library);
}

// `rows`' frames [first, first + count), linearly resampled to 16 rows of 10 coordinates.
std::vector<float> ResampleByHand(CoordinateView rows, int64_t first, int64_t count) {
  std::vector<float> out;
  for (int s = 0; s < 16; ++s) {
    const double t = count > 1 ? s * (count - 1) / 15.0 : 0.0;
    const int64_t i = static_cast<int64_t>(std::floor(t));
    const int64_t j = std::min(i + 1, count - 1);
    for (int d = 0; d < 10; ++d) {
      const double a = rows.row(first + i)[d], b = rows.row(first + j)[d];
      out.push_back(static_cast<float>(a + (t - i) * (b - a)));
    }
  }
  return out;
}

struct Hit {
  int clip;
  int64_t first_frame, last_frame;
  double score;
};

// By definition: every window vector of the query's scale, the best of each allowed clip, ranked.
std::vector<Hit> BruteForce(const WindowVectorBaseline& baseline, const LibraryIndex& library,
                            CoordinateView query, int max_results,
                            const std::vector<bool>& allowed) {
  const int scale = baseline.ScaleFor(query.rows);
  const std::vector<float> q = ResampleByHand(query, 0, query.rows);
  std::map<int, Hit> best;
  for (int64_t w = 0; w < baseline.window_count(scale); ++w) {
    const WindowVectorBaseline::Window& window = baseline.window(scale, w);
    if (!allowed.empty() && !allowed[window.clip]) continue;
    const float* v = baseline.window_vector(scale, w);
    double squared = 0;
    for (size_t i = 0; i < q.size(); ++i) squared += (v[i] - q[i]) * (v[i] - q[i]);
    const Hit hit{window.clip, window.first_frame, window.last_frame, std::sqrt(squared / 16)};
    auto [it, inserted] = best.emplace(window.clip, hit);
    if (!inserted && hit.score < it->second.score) it->second = hit;
  }
  std::vector<Hit> hits;
  for (const auto& [clip, hit] : best) hits.push_back(hit);
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.score < b.score; });
  if (static_cast<int>(hits.size()) > max_results) hits.resize(max_results);
  (void)library;
  return hits;
}

TEST(WindowVectorBaselineTest, WindowsCoverEveryClipAndResampleItsFirstTenCoordinates) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary();
  auto baseline = WindowVectorBaseline::Build(*library, {});
  ASSERT_TRUE(baseline.ok()) << baseline.status();
  ASSERT_EQ((*baseline)->scale_count(), 4);
  EXPECT_EQ((*baseline)->window_frames(0), 15);
  EXPECT_EQ((*baseline)->window_frames(3), 120);
  for (int scale = 0; scale < 4; ++scale) {
    const int64_t length = (*baseline)->window_frames(scale);
    std::map<int, std::vector<WindowVectorBaseline::Window>> by_clip;
    for (int64_t w = 0; w < (*baseline)->window_count(scale); ++w) {
      const WindowVectorBaseline::Window& window = (*baseline)->window(scale, w);
      by_clip[window.clip].push_back(window);
      const std::vector<float> want =
          ResampleByHand(library->clip_coordinates(window.clip), window.first_frame,
                         window.last_frame - window.first_frame + 1);
      const float* got = (*baseline)->window_vector(scale, w);
      for (size_t i = 0; i < want.size(); ++i) ASSERT_NEAR(got[i], want[i], 1e-5) << w;
    }
    ASSERT_EQ(by_clip.size(), 6u);
    for (const auto& [clip, windows] : by_clip) {
      const int64_t frames = library->clip(clip).frame_count;
      if (frames <= length) {  // a short clip: one window, whole
        ASSERT_EQ(windows.size(), 1u);
        EXPECT_EQ(windows[0].first_frame, 0);
        EXPECT_EQ(windows[0].last_frame, frames - 1);
        continue;
      }
      EXPECT_EQ(windows.front().first_frame, 0);
      EXPECT_EQ(windows.back().last_frame, frames - 1);  // the clip's end is covered
      for (size_t i = 0; i < windows.size(); ++i) {
        EXPECT_EQ(windows[i].last_frame - windows[i].first_frame + 1, length);
        if (i > 0) {
          EXPECT_LE(windows[i].first_frame - windows[i - 1].first_frame, length / 8);
        }
      }
    }
  }
}

// Queries of several lengths (so every scale is searched), cut from the library and from noise
// it does not hold, with and without a filter: the FLANN forest with checks above the windows'
// count and the linear index give the brute force's clips, ranges and distances.
TEST(WindowVectorBaselineTest, TopHitsEqualBruteForce) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary();
  for (const WindowIndexKind kind : {WindowIndexKind::kKdForest, WindowIndexKind::kLinear}) {
    WindowBaselineOptions options;
    options.kind = kind;
    options.checks = 100000;  // more than every window: the forest searched exhaustively
    auto baseline = WindowVectorBaseline::Build(*library, options);
    ASSERT_TRUE(baseline.ok()) << baseline.status();
    const RowMatrixXf noise = testing::SmoothNoise(200, kDims, 99);
    const std::vector<CoordinateView> queries = {
        CoordinateView::Of(noise).middle_rows(0, 12),
        CoordinateView::Of(noise).middle_rows(5, 33),
        CoordinateView::Of(noise).middle_rows(50, 70),
        CoordinateView::Of(noise),
        library->clip_coordinates(4).middle_rows(101, 40),
        library->clip_coordinates(2)};  // the short clip, whole
    const std::vector<bool> allowed = {true, false, true, true, false, true};
    for (size_t q = 0; q < queries.size(); ++q) {
      for (const std::vector<bool>& filter : {std::vector<bool>(), allowed}) {
        const std::vector<SearchResult> got = (*baseline)->Search(queries[q], 4, filter);
        const std::vector<Hit> want = BruteForce(**baseline, *library, queries[q], 4, filter);
        ASSERT_EQ(got.size(), want.size()) << q;
        for (size_t i = 0; i < want.size(); ++i) {
          EXPECT_EQ(got[i].clip_index, want[i].clip) << q << " " << i;
          EXPECT_EQ(got[i].clip_id, 100 + want[i].clip);
          EXPECT_EQ(got[i].first_frame, want[i].first_frame) << q << " " << i;
          EXPECT_EQ(got[i].last_frame, want[i].last_frame) << q << " " << i;
          EXPECT_NEAR(got[i].score, want[i].score, 1e-4) << q << " " << i;
          if (!filter.empty()) {
            EXPECT_TRUE(filter[got[i].clip_index]);
          }
        }
        const std::vector<SearchResult> scan = (*baseline)->Search(queries[q], 4, filter, true);
        ASSERT_EQ(scan.size(), got.size());
        for (size_t i = 0; i < scan.size(); ++i) EXPECT_EQ(scan[i].clip_index, got[i].clip_index);
      }
      EXPECT_DOUBLE_EQ((*baseline)->WindowRecall(queries[q], 20), 1.0);
    }
  }
}

// A query that is exactly one of the library's windows finds that clip first, at that window,
// at distance 0, with the benchmark's default (approximate) index.
TEST(WindowVectorBaselineTest, ExactCopyOfAWindowFindsItsClipFirst) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary();
  auto baseline = WindowVectorBaseline::Build(*library, {});
  ASSERT_TRUE(baseline.ok()) << baseline.status();
  for (int scale = 0; scale < (*baseline)->scale_count(); ++scale) {
    for (int64_t w = 0; w < (*baseline)->window_count(scale); w += 7) {
      const WindowVectorBaseline::Window& window = (*baseline)->window(scale, w);
      const CoordinateView query =
          library->clip_coordinates(window.clip)
              .middle_rows(window.first_frame, window.last_frame - window.first_frame + 1);
      if ((*baseline)->ScaleFor(query.rows) != scale) continue;  // a short clip's whole window
      const std::vector<SearchResult> results = (*baseline)->Search(query, 3, {});
      ASSERT_FALSE(results.empty());
      EXPECT_EQ(results[0].clip_index, window.clip) << scale << " " << w;
      EXPECT_EQ(results[0].first_frame, window.first_frame) << scale << " " << w;
      EXPECT_NEAR(results[0].score, 0.0, 1e-5);
      EXPECT_EQ(results.size(), 3u);
    }
  }
}

TEST(WindowVectorBaselineTest, QueriesGoToTheNearestLengthByRatio) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary();
  auto baseline = WindowVectorBaseline::Build(*library, {});
  ASSERT_TRUE(baseline.ok()) << baseline.status();
  EXPECT_EQ((*baseline)->ScaleFor(1), 0);
  EXPECT_EQ((*baseline)->ScaleFor(21), 0);  // 15 * sqrt(2) = 21.2
  EXPECT_EQ((*baseline)->ScaleFor(22), 1);
  EXPECT_EQ((*baseline)->ScaleFor(84), 2);  // 60 * sqrt(2) = 84.9
  EXPECT_EQ((*baseline)->ScaleFor(85), 3);
  EXPECT_EQ((*baseline)->ScaleFor(100000), 3);
  EXPECT_GT((*baseline)->memory_bytes(), 0);
}

// The retrieval evaluation's hook for a baseline (testing::RetrievalOptions::baseline): called once
// a query with the query's findable clips, and scored as the searches it stands beside are; a
// baseline answering with the exact search's results scores the exact search's figures.
TEST(WindowVectorBaselineTest, EvaluationScoresTheBaselineOnTheSameQueries) {
  const std::unique_ptr<LibraryIndex> library = NoiseLibrary(0);  // ids = indices, as it needs
  const std::vector<std::string> labels = {"a", "b", "a", "b", "a", "b"};
  testing::RetrievalOptions options;
  options.precision_at = 2;
  options.wide_precision_at = 3;
  options.recall_at = 3;
  options.exact_every = 1;
  int calls = 0;
  options.baseline = [&](CoordinateView query, const SearchParams& params) {
    ++calls;
    EXPECT_EQ(params.clip_ids.size(), 5u);  // every clip but the query
    EXPECT_EQ(params.max_results, 3);
    return ExactSearch(*library, query, params)->results;
  };
  absl::StatusOr<testing::RetrievalReport> report =
      testing::EvaluateRetrieval(*library, labels, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(calls, 6);
  EXPECT_EQ(report->baseline.queries, 6);
  EXPECT_DOUBLE_EQ(report->baseline.precision, report->exact_precision);
  EXPECT_DOUBLE_EQ(report->baseline.wide_precision, report->exact_wide_precision);
  EXPECT_DOUBLE_EQ(report->baseline.recall, 1.0);
  EXPECT_GT(report->baseline.latency_p50_ms, 0.0);

  // The window baseline itself, and a baseline that finds nothing.
  auto baseline = WindowVectorBaseline::Build(*library, {});
  ASSERT_TRUE(baseline.ok()) << baseline.status();
  options.baseline = [&](CoordinateView query, const SearchParams& params) {
    std::vector<bool> allowed(library->clip_count(), false);
    for (const int64_t id : params.clip_ids) allowed[library->FindClip(id)] = true;
    return (*baseline)->Search(query, params.max_results, allowed);
  };
  report = testing::EvaluateRetrieval(*library, labels, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->baseline.queries, 6);
  options.baseline = [](CoordinateView, const SearchParams&) {
    return std::vector<SearchResult>();
  };
  report = testing::EvaluateRetrieval(*library, labels, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->baseline.precision, 0.0);
  EXPECT_EQ(report->baseline.recall, 0.0);
}

}  // namespace
}  // namespace motiondb
