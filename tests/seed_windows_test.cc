// The fast search's seeds by window (LibraryIndex::NearestWindows) against brute force: the
// window tree, the window tree under a filter, a library grown clip by clip, the scan, the
// window built once under concurrent searches.
#include <algorithm>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/motion_search.h"
#include "tests/search_test_data.h"

namespace motiondb {
namespace {

constexpr int kDims = 8;
constexpr int kTreeDims = 5;
constexpr double kRate = 30.0;

// Three clips of smooth noise, one shorter than a window so that every pose of it is clamped.
std::vector<LibraryClip> NoiseClips() {
  std::vector<LibraryClip> clips;
  const int64_t lengths[] = {700, 5, 450};
  for (int c = 0; c < 3; ++c) {
    clips.push_back({10 + c, "noise", {}, testing::SmoothNoise(lengths[c], kDims, 40 + c)});
  }
  return clips;
}

// By definition, independently of the index: the squared distances of the poses at f - w, f and
// f + w (clamped to each side's own rows) summed over the first `dims` coordinates, for every
// `every`-th global frame of the allowed clips, square-rooted and sorted.
std::vector<float> BruteForceWindows(const LibraryIndex& library, CoordinateView query,
                                     int64_t frame, int dims, const std::vector<bool>& allowed,
                                     int every) {
  const int w = library.window_frames();
  const auto pose = [](CoordinateView rows, int64_t at) {
    return rows.row(std::clamp<int64_t>(at, 0, rows.rows - 1));
  };
  std::vector<float> distances;
  for (int c = 0; c < library.clip_count(); ++c) {
    if (!allowed.empty() && !allowed[c]) continue;
    const CoordinateView clip = library.clip_coordinates(c);
    for (int64_t f = 0; f < clip.rows; ++f) {
      if ((library.clip(c).first_frame + f) % every != 0) continue;
      float squared = 0;
      for (const int offset : {-w, 0, w}) {
        const float d = Distance(pose(query, frame + offset), pose(clip, f + offset), dims);
        squared += d * d;
      }
      distances.push_back(std::sqrt(squared));
    }
  }
  std::sort(distances.begin(), distances.end());
  return distances;
}

// The index's answers (tree, tree with a filter, scan of one clip) against brute force, for
// queries at the start, middle and end of a clip of the library and of a noise query.
void ExpectWindowsAgreeWithBruteForce(const LibraryIndex& library) {
  ASSERT_EQ(library.window_frames(), 8);  // lround(0.25 s x 30 Hz)
  const RowMatrixXf outside = testing::SmoothNoise(60, kDims, 99);
  const CoordinateView queries[] = {library.clip_coordinates(0), CoordinateView::Of(outside)};
  // Filters: none, all but the shortest clip (the tree, filtered after), and one clip of fewer
  // than half the frames (a scan).
  std::vector<bool> all_but_one(library.clip_count(), true), one(library.clip_count(), false);
  all_but_one[1] = false;
  for (int c = 0; c < library.clip_count(); ++c) {
    const int64_t frames = library.clip(c).frame_count;
    if (frames >= 40 && 2 * frames < library.total_frames()) {
      one[c] = true;
      break;
    }
  }
  const std::vector<bool> filters[] = {std::vector<bool>(), all_but_one, one};
  for (const CoordinateView& query : queries) {
    for (const int64_t frame : {int64_t{0}, int64_t{3}, query.rows / 2, query.rows - 1}) {
      for (const std::vector<bool>& allowed : filters) {
        const int every = &allowed == &filters[2] ? 1 : library.tree_every();
        const std::vector<float> expected =
            BruteForceWindows(library, query, frame, kTreeDims, allowed, every);
        for (const int k : {1, 40}) {
          const std::vector<Neighbour> found = library.NearestWindows(
              query, frame, kTreeDims, k, 0.0f, FrameSelector::OfClips(allowed));
          ASSERT_EQ(found.size(), static_cast<size_t>(k));
          for (int i = 0; i < k; ++i) {
            EXPECT_EQ(found[i].frame % every, 0) << i;
            EXPECT_NEAR(found[i].distance, expected[i], 1e-4 * (1 + expected[i]))
                << "frame " << frame << ", neighbour " << i;
            if (!allowed.empty()) {
              EXPECT_TRUE(allowed[library.Locate(found[i].frame).first]);
            }
          }
        }
      }
    }
  }
}

TEST(NearestWindows, AgreeWithBruteForce) {
  for (const bool coarse : {false, true}) {
    LibraryIndexOptions options;
    options.ann_dims = kTreeDims;
    options.coarse_tree = coarse;
    const auto library = LibraryIndex::Build(NoiseClips(), kRate, options);
    ASSERT_TRUE(library.ok()) << library.status();
    SCOPED_TRACE(coarse ? "every other frame in the tree" : "every frame in the tree");
    ExpectWindowsAgreeWithBruteForce(**library);
  }
}

// A clip added later has its windows in a second tree, searched in the first tree's basis.
TEST(NearestWindows, AgreeWithBruteForceInALibraryGrownClipByClip) {
  std::vector<LibraryClip> clips = NoiseClips();
  clips[2] = {12, "long noise", {}, testing::SmoothNoise(1200, kDims, 42)};
  LibraryIndexOptions options;
  options.ann_dims = kTreeDims;
  auto grown = LibraryIndex::Build(std::move(clips), kRate, options);
  ASSERT_TRUE(grown.ok()) << grown.status();
  // Windows built before the addition are shared with the grown library.
  ASSERT_FALSE(
      (*grown)->NearestWindows((*grown)->clip_coordinates(0), 5, kTreeDims, 3, 0.0f, {}).empty());
  auto added = (*grown)->WithClips({{13, "added", {}, testing::SmoothNoise(101, kDims, 43)}});
  ASSERT_TRUE(added.ok()) << added.status();
  ASSERT_EQ((*added)->block_count(), 2);
  EXPECT_GT((*added)->tree_bytes(), (*grown)->tree_bytes());  // the first block's windows too
  ExpectWindowsAgreeWithBruteForce(**added);
}

// Searches over other dimensions than the tree's scan every frame, as do searches of a few
// clips: neither builds the window trees.
TEST(NearestWindows, OverOtherDimensionsScan) {
  const auto library = LibraryIndex::Build(NoiseClips(), kRate, {kTreeDims, 32, true});
  ASSERT_TRUE(library.ok());
  const int64_t unbuilt_bytes = (*library)->tree_bytes();
  ASSERT_EQ((*library)
                ->NearestWindows((*library)->clip_coordinates(2), 100, kTreeDims, 10, 0.0f,
                                 FrameSelector::OfClips({false, false, true}))
                .size(),
            10u);
  const CoordinateView query = (*library)->clip_coordinates(2);
  const std::vector<float> expected = BruteForceWindows(**library, query, 100, 7, {}, 1);
  const std::vector<Neighbour> found = (*library)->NearestWindows(query, 100, 7, 30, 0.0f, {});
  ASSERT_EQ(found.size(), 30u);
  for (size_t i = 0; i < found.size(); ++i) EXPECT_NEAR(found[i].distance, expected[i], 1e-4);
  EXPECT_EQ(found[0].distance, 0.0f);  // the query's own frame
  EXPECT_EQ((*library)->tree_bytes(), unbuilt_bytes);
}

TEST(NearestWindows, WithoutWindowsAreTheNearestFrames) {
  LibraryIndexOptions options;
  options.ann_dims = kTreeDims;
  options.seed_window_s = 0;
  const auto library = LibraryIndex::Build(NoiseClips(), kRate, options);
  ASSERT_TRUE(library.ok());
  EXPECT_EQ((*library)->window_frames(), 0);
  const CoordinateView query = (*library)->clip_coordinates(0);
  const std::vector<Neighbour> windows =
      (*library)->NearestWindows(query, 50, kTreeDims, 20, 0.0f, {});
  const std::vector<Neighbour> frames = (*library)->Nearest(query.row(50), kTreeDims, 20, 0.0f, {});
  ASSERT_EQ(windows.size(), frames.size());
  for (size_t i = 0; i < windows.size(); ++i) {
    EXPECT_EQ(windows[i].frame, frames[i].frame);
    EXPECT_EQ(windows[i].distance, frames[i].distance);
  }
}

TEST(NearestWindows, WindowLengthOutOfRangeIsRefused) {
  for (const double seconds : {-0.1, kMaxSeedWindowS + 0.5, std::nan("")}) {
    LibraryIndexOptions options;
    options.seed_window_s = seconds;
    const auto library = LibraryIndex::Build(NoiseClips(), kRate, options);
    EXPECT_EQ(library.status().code(), absl::StatusCode::kInvalidArgument) << seconds;
    EXPECT_NE(library.status().message().find("seed_window_s"), std::string::npos);
  }
}

// The first window searches build the windows: searches at once build them once, and every one
// gets the answer of a search alone.
TEST(NearestWindows, ConcurrentFirstSearchesAgree) {
  LibraryIndexOptions options;
  options.ann_dims = kTreeDims;
  const auto reference = LibraryIndex::Build(NoiseClips(), kRate, options);
  const auto library = LibraryIndex::Build(NoiseClips(), kRate, options);
  ASSERT_TRUE(reference.ok() && library.ok());
  const int64_t unbuilt_bytes = (*library)->tree_bytes();
  const CoordinateView query = (*reference)->clip_coordinates(2);
  const std::vector<Neighbour> expected =
      (*reference)->NearestWindows(query, 200, kTreeDims, 25, 0.0f, {});
  std::vector<std::vector<Neighbour>> found(4);
  std::vector<std::thread> threads;
  for (auto& answer : found) {
    threads.emplace_back(
        [&] { answer = (*library)->NearestWindows(query, 200, kTreeDims, 25, 0.0f, {}); });
  }
  for (std::thread& thread : threads) thread.join();
  for (const auto& answer : found) {
    ASSERT_EQ(answer.size(), expected.size());
    for (size_t i = 0; i < answer.size(); ++i) {
      EXPECT_EQ(answer[i].frame, expected[i].frame);
      EXPECT_EQ(answer[i].distance, expected[i].distance);
    }
  }
  // The windows (15 floats a tree point) and their tree now count in the index's memory.
  EXPECT_GE((*library)->tree_bytes(),
            unbuilt_bytes + (*library)->total_frames() / (*library)->tree_every() * 15 * 4);
}

// Clips at 120 Hz, six holding the query's peak pose for 4 s: 500 seed windows pile into the
// holds, fewer places than two a result for 20 results; the default count takes them again, twice
// as many, until they reach that; a count the search is given is kept. (Since each seed moves to
// the full-rate frame nearest its warp's pinned pose, the given 500 fill the 20 results too.)
TEST(DefaultSeeds, AreTakenAgainWhileTooFewPlacesToFillTheResults) {
  constexpr int kQueryFrames = 240;
  const RowMatrixXf pattern = testing::Pattern(kQueryFrames, kDims);
  const auto library = LibraryIndex::Build(testing::HeldPoseClips(kDims), 120.0, {});
  ASSERT_TRUE(library.ok()) << library.status();
  SearchParams params;
  params.seed_selection = SeedSelection::kNearestWindows;
  params.characteristic_frame = kQueryFrames / 2;
  params.neighbours = 500;
  const SearchResponse given = *Search(**library, CoordinateView::Of(pattern), params);
  EXPECT_EQ(given.stats.seeds, 500);
  EXPECT_LT(given.stats.clusters, 2 * params.max_results);
  params.neighbours = 0;  // the default, 500 first
  const SearchResponse found = *Search(**library, CoordinateView::Of(pattern), params);
  EXPECT_GT(found.stats.seeds, 500);
  EXPECT_GE(found.stats.clusters, 2 * params.max_results);
  EXPECT_EQ(found.results.size(), 20u);
}

}  // namespace
}  // namespace motiondb
