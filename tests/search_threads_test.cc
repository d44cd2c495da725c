// SearchParams::threads: a fast search on several threads returns what it returns on one, bit
// for bit, whatever the threads' timing, with every option that changes what the warps and
// settles see (filters, an excluded range, a second anchor, seed windows, the full rate's
// tail at 120 Hz).
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/motion_search.h"
#include "tests/search_test_data.h"
#include "util/parallel_for.h"

namespace motiondb {
namespace {

constexpr int kDims = 10;

// Many clips, each holding the pattern at a few speeds and strengths, so that the warps' pool
// fills, its threshold falls and the settles' bound tightens while the threads run.
std::unique_ptr<LibraryIndex> PlantedLibrary(double rate, int clips, int64_t frames) {
  const int pattern_frames = static_cast<int>(rate * 4 / 3);
  std::vector<LibraryClip> library;
  for (int c = 0; c < clips; ++c) {
    RowMatrixXf curve = testing::SmoothNoise(frames, kDims, 200 + c);
    for (int copy = 0; copy < 3; ++copy) {
      const int length = pattern_frames * (3 + (c + copy) % 4) / 4;
      const float strength = 0.6f + 0.1f * static_cast<float>((c * 3 + copy) % 5);
      testing::Plant(curve, strength * testing::Pattern(length, kDims),
                     (copy + 1) * frames / 4 - length / 2);
    }
    library.push_back({static_cast<int64_t>(1000 + c),
                       "clip" + std::to_string(c),
                       {c % 3 == 0 ? "walk" : "run"},
                       std::move(curve)});
  }
  return *LibraryIndex::Build(std::move(library), rate, {});
}

void ExpectSameResults(const SearchResponse& one, const SearchResponse& many,
                       const std::string& what) {
  ASSERT_EQ(one.results.size(), many.results.size()) << what;
  for (size_t i = 0; i < one.results.size(); ++i) {
    const SearchResult& a = one.results[i];
    const SearchResult& b = many.results[i];
    EXPECT_EQ(a.clip_id, b.clip_id) << what << ", result " << i;
    EXPECT_EQ(a.first_frame, b.first_frame) << what << ", result " << i;
    EXPECT_EQ(a.last_frame, b.last_frame) << what << ", result " << i;
    EXPECT_EQ(a.score, b.score) << what << ", result " << i;
    EXPECT_EQ(a.seed_frame, b.seed_frame) << what << ", result " << i;
    EXPECT_EQ(a.path, b.path) << what << ", result " << i;
  }
  EXPECT_EQ(one.stats.seeds, many.stats.seeds) << what;
  EXPECT_EQ(one.stats.clusters, many.stats.clusters) << what;
}

struct Variant {
  std::string name;
  SearchParams params;
};

std::vector<Variant> Variants(const LibraryIndex& library) {
  std::vector<Variant> variants;
  const auto add = [&](std::string name, const auto& change) {
    SearchParams params;
    params.max_results = 10;
    change(params);
    variants.push_back({std::move(name), std::move(params)});
  };
  add("defaults", [](SearchParams&) {});
  add("with paths", [](SearchParams& p) { p.return_path = true; });
  add("without refinement", [](SearchParams& p) { p.refine = false; });
  add("many results", [](SearchParams& p) { p.max_results = 60; });
  add("few seeds", [](SearchParams& p) { p.neighbours = 50; });
  add("always a second anchor", [](SearchParams& p) { p.second_anchor_scatter = 0.01; });
  add("seed windows", [](SearchParams& p) { p.seed_selection = SeedSelection::kNearestWindows; });
  add("tag filter", [](SearchParams& p) { p.tags = {"walk"}; });
  add("clip filter", [&](SearchParams& p) {
    for (int c = 0; c < library.clip_count(); c += 2) p.clip_ids.push_back(library.clip(c).clip_id);
  });
  add("an excluded range", [&](SearchParams& p) {
    p.excluded = ExcludedRange{library.clip(1).clip_id, 0, library.clip_coordinates(1).rows / 2};
  });
  return variants;
}

void ExpectThreadsChangeNothing(const LibraryIndex& library, int pattern_frames) {
  const RowMatrixXf queries[] = {testing::Pattern(pattern_frames, kDims),
                                 0.8f * testing::Pattern(pattern_frames * 3 / 4, kDims)};
  for (const RowMatrixXf& query : queries) {
    const CoordinateView q = CoordinateView::Of(query);
    for (const Variant& variant : Variants(library)) {
      SearchParams params = variant.params;
      params.threads = 1;
      const absl::StatusOr<SearchResponse> one = Search(library, q, params);
      ASSERT_TRUE(one.ok()) << variant.name << ": " << one.status();
      ASSERT_FALSE(one->results.empty()) << variant.name;
      EXPECT_EQ(one->stats.threads, 1);
      // Several runs: the threads interleave differently each time.
      for (const int threads : {2, 3, 8, 2, 8}) {
        params.threads = threads;
        const absl::StatusOr<SearchResponse> many = Search(library, q, params);
        ASSERT_TRUE(many.ok()) << variant.name << ": " << many.status();
        EXPECT_EQ(many->stats.threads, threads);
        ExpectSameResults(*one, *many,
                          variant.name + ", " + std::to_string(threads) + " threads, query of " +
                              std::to_string(query.rows()) + " frames");
      }
    }
  }
}

TEST(SearchThreads, ChangeNothingAt30Hz) {
  const std::unique_ptr<LibraryIndex> library = PlantedLibrary(30, 40, 600);
  ExpectThreadsChangeNothing(*library, 40);
}

// At 120 Hz only the best two thirds of the refined pool are always settled at the full rate;
// the rest only while too few clips hold a result, one thread's tail.
TEST(SearchThreads, ChangeNothingAt120Hz) {
  const std::unique_ptr<LibraryIndex> library = PlantedLibrary(120, 12, 2400);
  ExpectThreadsChangeNothing(*library, 160);
}

TEST(SearchThreads, ZeroIsOnePerCoreAndTooManyAreRefused) {
  const std::unique_ptr<LibraryIndex> library = PlantedLibrary(30, 4, 300);
  const RowMatrixXf query = testing::Pattern(40, kDims);
  SearchParams params;
  params.threads = 0;
  const absl::StatusOr<SearchResponse> all = Search(*library, CoordinateView::Of(query), params);
  ASSERT_TRUE(all.ok()) << all.status();
  EXPECT_EQ(all->stats.threads, ThreadsFor(0));
  for (const int bad : {-1, 1025}) {
    params.threads = bad;
    const absl::Status status = Search(*library, CoordinateView::Of(query), params).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(status.message().find("threads"), std::string::npos) << status;
  }
}

TEST(SearchThreads, StopWhenTheCallerSaysSo) {
  const std::unique_ptr<LibraryIndex> library = PlantedLibrary(30, 20, 600);
  const RowMatrixXf query = testing::Pattern(40, kDims);
  SearchParams params;
  params.threads = 4;
  params.should_stop = [] { return true; };
  EXPECT_EQ(Search(*library, CoordinateView::Of(query), params).status().code(),
            absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace motiondb
