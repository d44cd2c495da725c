// The fast search's seeds as distinct places (LibraryIndex::NearestPlaces) against brute force,
// and the exact search's threads: the same results however many scan the library.
#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "tests/search_test_data.h"

namespace motiondb {
namespace {

constexpr int kDims = 12;
constexpr int kTreeDims = 10;

const float* FrameRow(const LibraryIndex& library, int64_t frame) {
  const auto [clip, local] = library.Locate(frame);
  return library.clip_coordinates(clip).row(local);
}

// By definition: every frame of the allowed clips (of a one-block library's kd-tree: every
// `every`-th) by distance to `point` (ties to the earlier frame), each kept unless a kept one of
// its clip lies within `separation` - 1 frames, the first k kept.
std::vector<int64_t> BruteForcePlaces(const LibraryIndex& library, const float* point, int dims,
                                      int k, int64_t separation, const std::vector<bool>& allowed,
                                      int every = 1) {
  std::vector<std::pair<float, int64_t>> frames;
  for (int c = 0; c < library.clip_count(); ++c) {
    if (!allowed.empty() && !allowed[c]) continue;
    const CoordinateView clip = library.clip_coordinates(c);
    for (int64_t f = 0; f < clip.rows; ++f) {
      const int64_t frame = library.clip(c).first_frame + f;
      if (frame % every == 0) frames.emplace_back(Distance(point, clip.row(f), dims), frame);
    }
  }
  std::sort(frames.begin(), frames.end());
  std::vector<int64_t> kept;
  for (const auto& [distance, frame] : frames) {
    if (static_cast<int>(kept.size()) == k) break;
    const int clip = library.Locate(frame).first;
    const bool near_kept = std::any_of(kept.begin(), kept.end(), [&](int64_t other) {
      return library.Locate(other).first == clip && std::abs(other - frame) < separation;
    });
    if (!near_kept) kept.push_back(frame);
  }
  return kept;
}

std::vector<int64_t> Frames(const std::vector<Neighbour>& neighbours) {
  std::vector<int64_t> frames;
  for (const Neighbour& n : neighbours) frames.push_back(n.frame);
  return frames;
}

// Clips whose distance to `centre` over time is a row of V-shaped wells, one minimum each, at
// least three separations apart: the nearest places are the wells' bottoms. The offsets lie in
// the first six dimensions, so that six and ten dimensions measure the same distance.
std::unique_ptr<LibraryIndex> WellLibrary(const std::vector<float>& centre, int64_t separation,
                                          std::vector<int64_t>* bottoms) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> depth(1.0f, 2.0f), unit(-1.0f, 1.0f);
  std::vector<LibraryClip> clips;
  int64_t first_frame = 0;
  for (int c = 0; c < 5; ++c) {
    const int64_t frames = 400 + 60 * c;
    std::vector<int64_t> wells;
    for (int64_t at = 20 + c * 7; at < frames - 20; at += 3 * separation + rng() % 25) {
      wells.push_back(at);
      bottoms->push_back(first_frame + at);
    }
    std::vector<float> well_depth(wells.size());
    for (float& d : well_depth) d = depth(rng);
    RowMatrixXf coordinates(frames, kDims);
    for (int64_t f = 0; f < frames; ++f) {
      size_t w = 0;  // the nearest well in time
      for (size_t i = 1; i < wells.size(); ++i) {
        if (std::abs(wells[i] - f) < std::abs(wells[w] - f)) w = i;
      }
      const float radius = well_depth[w] + 0.5f * static_cast<float>(std::abs(wells[w] - f));
      float direction[6], norm = 0;
      for (float& d : direction) {
        d = unit(rng);
        norm += d * d;
      }
      for (int k = 0; k < kDims; ++k) {
        coordinates(f, k) = centre[k] + (k < 6 ? radius * direction[k] / std::sqrt(norm) : 0.0f);
      }
    }
    clips.push_back({c, "wells", {}, std::move(coordinates)});
    first_frame += frames;
  }
  // Every frame in the tree: the wells' bottoms lie on any frame.
  return *LibraryIndex::Build(std::move(clips), 30.0, {kTreeDims, 32, /*coarse_tree=*/false});
}

TEST(NearestPlaces, AreTheBottomsOfTheWellsFirstAsBruteForceFindsThem) {
  const std::vector<float> centre(kDims, 0.25f);
  const int64_t separation = 20;
  std::vector<int64_t> bottoms;
  const std::unique_ptr<LibraryIndex> library = WellLibrary(centre, separation, &bottoms);
  ASSERT_GE(bottoms.size(), 30u);
  std::vector<bool> all_but_one(library->clip_count(), true), one(library->clip_count(), false);
  all_but_one[2] = false;
  one[2] = true;
  // The kd-tree, the kd-tree under a filter, the linear scan of one clip, and of other dims.
  for (const auto& [dims, allowed] : {std::pair<int, std::vector<bool>>{kTreeDims, {}},
                                      {kTreeDims, all_but_one},
                                      {kTreeDims, one},
                                      {6, {}}}) {
    // Up to the number of wells, the places are their bottoms (every slope frame a
    // separation away from one is farther than any bottom).
    const int wells =
        static_cast<int>(std::count_if(bottoms.begin(), bottoms.end(), [&](int64_t b) {
          return allowed.empty() || allowed[library->Locate(b).first];
        }));
    for (int k : {1, 7, wells}) {
      const std::vector<int64_t> expected =
          BruteForcePlaces(*library, centre.data(), dims, k, separation, allowed);
      const std::vector<Neighbour> found = library->NearestPlaces(
          centre.data(), dims, k, separation, 0.0f, FrameSelector::OfClips(allowed));
      EXPECT_EQ(Frames(found), expected) << "dims " << dims << ", k " << k;
      for (const Neighbour& n : found) {
        EXPECT_NE(std::find(bottoms.begin(), bottoms.end(), n.frame), bottoms.end());
        EXPECT_NEAR(n.distance, Distance(centre.data(), FrameRow(*library, n.frame), dims), 1e-5);
      }
    }
    // Beyond, slopes give places too, after every bottom.
    const std::vector<Neighbour> found = library->NearestPlaces(
        centre.data(), dims, 1000, separation, 0.0f, FrameSelector::OfClips(allowed));
    EXPECT_GT(static_cast<int>(found.size()), wells);
    const std::vector<int64_t> frames = Frames(found);
    for (int64_t bottom : bottoms) {
      if (!allowed.empty() && !allowed[library->Locate(bottom).first]) continue;
      EXPECT_NE(std::find(frames.begin(), frames.end(), bottom), frames.end()) << bottom;
    }
  }
}

// On noise, where a clip's distance to the point rises and falls at random: places are nearest
// first, never closer than the separation in one clip, the first is the nearest frame of all,
// and most of brute force's places are found (720 of 800 here: where the places' neighbourhoods
// chain, which are kept depends on the order the kd-tree meets the frames in).
TEST(NearestPlaces, OnNoiseAreSeparatedAndAgreeWithBruteForce) {
  // A tree of every frame, and one of every eighth (seeds at about 15 Hz from 120 Hz).
  for (const bool coarse : {false, true}) {
    SCOPED_TRACE(coarse);
    std::vector<LibraryClip> clips;
    for (int c = 0; c < 4; ++c) {
      clips.push_back({c, "noise", {}, testing::SmoothNoise(1500, kDims, 40 + c)});
    }
    const std::unique_ptr<LibraryIndex> library =
        *LibraryIndex::Build(std::move(clips), 120.0, {kTreeDims, 32, coarse});
    const int every = library->tree_every();
    ASSERT_EQ(every, coarse ? 8 : 1);
    std::mt19937 rng(8);
    int found_total = 0, expected_total = 0;
    for (int trial = 0; trial < 20; ++trial) {
      const float* point = FrameRow(*library, rng() % library->total_frames());
      const int64_t separation = 5 + trial % 4 * 10;
      // 40 places of the 6,000 frames at most 35 apart: there are always enough.
      const std::vector<Neighbour> found =
          library->NearestPlaces(point, kTreeDims, 40, separation, 0.0f, {});
      ASSERT_EQ(found.size(), 40u);
      if (every == 1) {
        EXPECT_EQ(found[0].distance, 0.0f);
      }
      for (size_t i = 0; i < found.size(); ++i) {
        EXPECT_EQ(found[i].frame % every, 0);
        if (i > 0) {
          EXPECT_LE(found[i - 1].distance, found[i].distance);
        }
        for (size_t j = 0; j < i; ++j) {
          const auto [ci, fi] = library->Locate(found[i].frame);
          const auto [cj, fj] = library->Locate(found[j].frame);
          EXPECT_TRUE(ci != cj || std::abs(fi - fj) >= separation) << found[i].frame;
        }
      }
      const std::vector<int64_t> expected =
          BruteForcePlaces(*library, point, kTreeDims, 40, separation, {}, every);
      const std::vector<int64_t> frames = Frames(found);
      for (int64_t frame : expected) {
        found_total += std::find(frames.begin(), frames.end(), frame) != frames.end();
      }
      expected_total += static_cast<int>(expected.size());
    }
    EXPECT_GE(found_total, 0.85 * expected_total) << found_total << " of " << expected_total;
  }
}

// Twelve clips of noise with the pattern planted in some, at several speeds.
std::unique_ptr<LibraryIndex> PlantedLibrary() {
  std::vector<LibraryClip> clips;
  for (int c = 0; c < 12; ++c) {
    RowMatrixXf curve = testing::SmoothNoise(300 + 37 * c, kDims, 90 + c);
    if (c % 3 != 2) testing::Plant(curve, testing::Pattern(32 + 2 * c, kDims), 40 + 11 * c);
    clips.push_back({c, "clip", {}, std::move(curve)});
  }
  return *LibraryIndex::Build(std::move(clips), 30.0, {});
}

TEST(ExactSearchThreads, GiveTheSameResultsBitForBit) {
  const std::unique_ptr<LibraryIndex> library = PlantedLibrary();
  std::mt19937 rng(4);
  for (int trial = 0; trial < 6; ++trial) {
    // Queries: the pattern, and stretches of the library itself.
    RowMatrixXf query = testing::Pattern(36, kDims);
    if (trial > 0) {
      const int clip = static_cast<int>(rng() % library->clip_count());
      const CoordinateView rows = library->clip_coordinates(clip);
      query = library->CopyClipCoordinates(clip).middleRows(rng() % (rows.rows - 50), 30);
    }
    SearchParams params;
    params.max_results = 4 + trial * 3;
    params.slope_limit = 2 + trial % 2;
    params.max_overlap = trial % 2 == 0 ? 0.5 : 0.2;
    params.exact_threads = 1;
    const SearchResponse one = *ExactSearch(*library, CoordinateView::Of(query), params);
    ASSERT_FALSE(one.results.empty());
    for (int threads : {2, 3, 8}) {
      params.exact_threads = threads;
      const SearchResponse many = *ExactSearch(*library, CoordinateView::Of(query), params);
      ASSERT_EQ(many.results.size(), one.results.size()) << threads << " threads";
      for (size_t i = 0; i < one.results.size(); ++i) {
        const SearchResult &a = one.results[i], &b = many.results[i];
        EXPECT_EQ(std::tie(a.clip_index, a.first_frame, a.last_frame, a.score),
                  std::tie(b.clip_index, b.first_frame, b.last_frame, b.score))
            << "trial " << trial << ", " << threads << " threads, #" << i;
      }
    }
  }
}

TEST(ExactSearchThreads, StopWhenTheCallerSays) {
  const std::unique_ptr<LibraryIndex> library = PlantedLibrary();
  const RowMatrixXf query = testing::Pattern(36, kDims);
  SearchParams params;
  params.exact_threads = 4;
  params.should_stop = [] { return true; };
  EXPECT_EQ(ExactSearch(*library, CoordinateView::Of(query), params).status().code(),
            absl::StatusCode::kCancelled);
  params.exact_threads = -1;
  EXPECT_EQ(ExactSearch(*library, CoordinateView::Of(query), params).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// Held poses give warps of equal cost that overlap one another: the scan keeps the one it met
// first (the earlier end), and ranking must break the tie the same way, or a result the scan
// kept is dropped at the end and the search returns fewer than max_results (18 of 20 here
// when ties went by start frame).
TEST(ExactSearch, FillsTheResultsAmongEqualWarps) {
  const std::unique_ptr<LibraryIndex> library =
      *LibraryIndex::Build(testing::HeldPoseClips(kDims), 120.0, {kTreeDims, 32, true});
  SearchParams params;
  params.characteristic_frame = 120;
  const SearchResponse exact =
      *ExactSearch(*library, CoordinateView::Of(testing::Pattern(240, kDims)), params);
  EXPECT_EQ(exact.results.size(), 20u);
}

// Every seed selection finds every planted copy that the exact search ranks first.
TEST(SeedSelection, EverySelectionFindsThePlantedCopies) {
  const std::unique_ptr<LibraryIndex> library = PlantedLibrary();
  const RowMatrixXf query = testing::Pattern(36, kDims);
  SearchParams params;
  params.max_results = 8;
  const SearchResponse exact = *ExactSearch(*library, CoordinateView::Of(query), params);
  ASSERT_EQ(exact.results.size(), 8u);
  for (SeedSelection selection : {SeedSelection::kDistinctPlaces, SeedSelection::kNearestFrames,
                                  SeedSelection::kNearestWindows}) {
    params.seed_selection = selection;
    const SearchResponse fast = *Search(*library, CoordinateView::Of(query), params);
    EXPECT_LE(fast.stats.clusters, fast.stats.seeds);
    for (const SearchResult& e : exact.results) {
      EXPECT_TRUE(std::any_of(fast.results.begin(), fast.results.end(),
                              [&](const SearchResult& f) { return Overlaps(e, f, 0.5); }))
          << "clip " << e.clip_index << " frame " << e.first_frame;
    }
  }
}

}  // namespace
}  // namespace motiondb
