// The library index, the fast search pipeline and the exact search, on synthetic projected
// libraries with planted patterns (no space needed).
#include <algorithm>
#include <atomic>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/characteristic_points.h"
#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "core/search/pose_search.h"
#include "core/search/warp/time_warp.h"
#include "tests/search_test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

constexpr int kDims = 12;

struct Planted {
  int clip;
  int64_t first;
  int64_t last;
};

// Three clips of noise; the pattern planted at known places, at 1x, 1.4x slower and 0.75x.
class SearchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<LibraryClip> clips;
    const std::vector<std::vector<std::pair<int64_t, int>>> plan = {
        {{100, 40}, {700, 56}}, {{300, 30}}, {}};
    for (size_t c = 0; c < plan.size(); ++c) {
      RowMatrixXf curve = testing::SmoothNoise(1200, kDims, 10 + c);
      for (const auto& [at, frames] : plan[c]) {
        testing::Plant(curve, testing::Pattern(frames, kDims), at);
        planted_.push_back({static_cast<int>(c), at, at + frames - 1});
      }
      clips.push_back({static_cast<int64_t>(100 + c),
                       "clip" + std::to_string(c),
                       {c == 1 ? "dance" : "walk"},
                       std::move(curve)});
    }
    library_ = *LibraryIndex::Build(std::move(clips), 30.0, {});
    query_ = testing::Pattern(40, kDims);
  }

  CoordinateView query() const { return CoordinateView::Of(query_); }

 public:
  // True when some result covers most of the planted range.
  static bool Found(const std::vector<SearchResult>& results, const Planted& p) {
    return std::any_of(results.begin(), results.end(), [&](const SearchResult& r) {
      const int64_t overlap = std::min(r.last_frame, p.last) - std::max(r.first_frame, p.first) + 1;
      return r.clip_index == p.clip && overlap > 0.7 * (p.last - p.first + 1);
    });
  }

 protected:
  std::unique_ptr<LibraryIndex> library_;
  RowMatrixXf query_;
  std::vector<Planted> planted_;
};

TEST(SearchStatsTest, AddStageStatsAddsCountsAndStageTimesButNotThreadsOrTotal) {
  SearchStats total;
  total.threads = 2;
  total.total_ms = 7;
  total.seeds = 1;
  total.warps_ms = 0.5;
  SearchStats part;
  part.threads = 4;
  part.total_ms = 100;
  part.seeds = 10;
  part.clusters = 3;
  part.warps = 5;
  part.cells = 40;
  part.pruned_blocks = 6;
  part.characteristic_ms = 0.25;
  part.seeds_ms = 1;
  part.clusters_ms = 2;
  part.warps_ms = 3;
  part.refine_ms = 4;
  part.ranking_ms = 5;
  AddStageStats(part, total);
  AddStageStats(part, total);
  EXPECT_EQ(total.seeds, 21);
  EXPECT_EQ(total.clusters, 6);
  EXPECT_EQ(total.warps, 10);
  EXPECT_EQ(total.cells, 80);
  EXPECT_EQ(total.pruned_blocks, 12);
  EXPECT_DOUBLE_EQ(total.characteristic_ms, 0.5);
  EXPECT_DOUBLE_EQ(total.seeds_ms, 2);
  EXPECT_DOUBLE_EQ(total.clusters_ms, 4);
  EXPECT_DOUBLE_EQ(total.warps_ms, 6.5);
  EXPECT_DOUBLE_EQ(total.refine_ms, 8);
  EXPECT_DOUBLE_EQ(total.ranking_ms, 10);
  EXPECT_EQ(total.threads, 2);
  EXPECT_DOUBLE_EQ(total.total_ms, 7);
}

TEST_F(SearchTest, LibraryMapsGlobalFramesToClips) {
  EXPECT_EQ(library_->total_frames(), 3600);
  EXPECT_EQ(library_->Locate(0), std::make_pair(0, int64_t{0}));
  EXPECT_EQ(library_->Locate(1199), std::make_pair(0, int64_t{1199}));
  EXPECT_EQ(library_->Locate(1200), std::make_pair(1, int64_t{0}));
  EXPECT_EQ(library_->Locate(3599), std::make_pair(2, int64_t{1199}));
  EXPECT_EQ(library_->FindClip(101), 1);
  EXPECT_EQ(library_->FindClip(7), -1);
}

// A library frame by global number.
const float* FrameRow(const LibraryIndex& library, int64_t frame) {
  const auto [clip, local] = library.Locate(frame);
  return library.clip_coordinates(clip).row(local);
}

// The k nearest frames over the tree's dims, nearest first, by brute force, and as the index
// finds them (kd-tree, kd-tree with a selector: its frames only, the multiples of tree_every();
// linear scan: every frame).
void ExpectNearestAgreesWithBruteForce(const LibraryIndex& library, int clips) {
  const int dims = library.ann_dims();
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const int64_t at = rng() % library.total_frames();
    const float* point = FrameRow(library, at);
    // Selectors: none, all but one clip (kd-tree, tested inside), one clip (linear scan), and
    // each of those but the 200 frames around the point's own (a stored query's range).
    std::vector<bool> all_but_one(clips, true), one(clips, false);
    all_but_one[1] = false;
    one[1] = true;
    const auto [own_clip, own_frame] = library.Locate(at);
    std::vector<FrameSelector> selectors;
    for (const std::vector<bool>& allowed : {std::vector<bool>(), all_but_one, one}) {
      selectors.push_back(FrameSelector::OfClips(allowed));
      selectors.push_back({.allowed = allowed,
                           .excluded_clip = own_clip,
                           .excluded_first = own_frame - 100,
                           .excluded_last = own_frame + 100});
    }
    for (const FrameSelector& selector : selectors) {
      SCOPED_TRACE(::testing::Message() << "selector " << &selector - selectors.data());
      // One clip of three is answered by a scan, the others by the tree.
      const int every = selector.allowed == one ? 1 : library.tree_every();
      std::vector<float> expected;
      for (int64_t f = 0; f < library.total_frames(); f += every) {
        const auto [clip, frame] = library.Locate(f);
        if (selector.Admits(clip, frame)) {
          expected.push_back(Distance(point, FrameRow(library, f), dims));
        }
      }
      std::sort(expected.begin(), expected.end());
      const std::vector<Neighbour> found = library.Nearest(point, dims, 50, 0.0f, selector);
      ASSERT_EQ(found.size(), 50u);
      for (size_t i = 0; i < found.size(); ++i) {
        EXPECT_EQ(found[i].frame % every, 0) << i;
        EXPECT_NEAR(found[i].distance, expected[i], 1e-4) << i;
        EXPECT_NEAR(found[i].distance, Distance(point, FrameRow(library, found[i].frame), dims),
                    1e-4);
        const auto [clip, frame] = library.Locate(found[i].frame);
        EXPECT_TRUE(selector.Admits(clip, frame));
      }
    }
    // Other dimensions than the tree's are answered by a scan of every frame.
    const std::vector<Neighbour> six = library.Nearest(point, 6, 5, 0.0f, {});
    EXPECT_EQ(six[0].distance, 0.0f);
  }
}

TEST_F(SearchTest, NearestAgreesWithBruteForce) { ExpectNearestAgreesWithBruteForce(*library_, 3); }

// The kd-tree holds about 15 frames a second (every eighth at 120 Hz), an eighth of the tree
// for the same clips; the linear scan still sees every frame.
TEST(LibraryIndexCoarseTree, HoldsAbout15FramesASecond) {
  const auto build = [](double rate, bool coarse) {
    std::vector<LibraryClip> clips;
    for (int c = 0; c < 3; ++c) {
      clips.push_back({c, "noise", {}, testing::SmoothNoise(1200, kDims, 60 + c)});
    }
    LibraryIndexOptions options;
    options.coarse_tree = coarse;
    return *LibraryIndex::Build(std::move(clips), rate, options);
  };
  const std::unique_ptr<LibraryIndex> coarse = build(120.0, true);
  EXPECT_EQ(coarse->tree_every(), 8);
  EXPECT_EQ(build(22.0, true)->tree_every(), 1);
  EXPECT_EQ(build(30.0, true)->tree_every(), 2);
  const std::unique_ptr<LibraryIndex> full = build(120.0, false);
  EXPECT_EQ(full->tree_every(), 1);
  EXPECT_LT(coarse->tree_bytes() * 6, full->tree_bytes());
  ExpectNearestAgreesWithBruteForce(*coarse, 3);
  ExpectNearestAgreesWithBruteForce(*full, 3);
}

// Clips added one at a time go into a second block beside the first; the index answers exactly
// as one built from all the clips at once, until the additions grow past a sixteenth of the
// frames and it is built anew.
TEST(LibraryIndexAdditions, AnswerAsABuildOfEveryClip) {
  std::vector<LibraryClip> clips;
  // Odd lengths, so that the second block starts between the kd-tree's frames (every second at
  // 30 Hz); the one-frame clip alone is a block with no tree frame.
  const std::vector<int64_t> lengths = {1501, 1500, 1, 60, 41, 1400};
  for (size_t c = 0; c < lengths.size(); ++c) {
    RowMatrixXf curve = testing::SmoothNoise(lengths[c], kDims, 80 + c);
    if (c == 3) testing::Plant(curve, testing::Pattern(40, kDims), 5);
    clips.push_back({static_cast<int64_t>(10 + c), "clip" + std::to_string(c), {}, curve});
  }
  std::unique_ptr<LibraryIndex> grown =
      *LibraryIndex::Build({clips[0], clips[1]}, 30.0, LibraryIndexOptions());
  for (size_t c = 2; c < clips.size(); ++c) {
    SCOPED_TRACE("after clip " + std::to_string(c));
    grown = *grown->WithClips({clips[c]});
    // The three small clips share the second block; the large last one makes a full build.
    EXPECT_EQ(grown->block_count(), c + 1 < clips.size() ? 2 : 1);
    const std::vector<LibraryClip> so_far(clips.begin(), clips.begin() + c + 1);
    const std::unique_ptr<LibraryIndex> built =
        *LibraryIndex::Build(so_far, 30.0, LibraryIndexOptions());
    ASSERT_EQ(grown->total_frames(), built->total_frames());
    ASSERT_EQ(grown->clip_count(), built->clip_count());
    for (int i = 0; i < built->clip_count(); ++i) {
      EXPECT_EQ(grown->clip(i).clip_id, built->clip(i).clip_id);
      EXPECT_EQ(grown->clip(i).first_frame, built->clip(i).first_frame);
      EXPECT_EQ(grown->CopyClipCoordinates(i), built->CopyClipCoordinates(i));
      EXPECT_EQ(grown->FindClip(built->clip(i).clip_id), i);
    }
    ExpectNearestAgreesWithBruteForce(*grown, grown->clip_count());
    const RowMatrixXf query = testing::Pattern(40, kDims);
    const SearchResponse from_grown = *Search(*grown, CoordinateView::Of(query), {});
    const SearchResponse from_built = *Search(*built, CoordinateView::Of(query), {});
    ASSERT_EQ(from_grown.results.size(), from_built.results.size());
    for (size_t r = 0; r < from_built.results.size(); ++r) {
      EXPECT_EQ(from_grown.results[r].clip_id, from_built.results[r].clip_id);
      EXPECT_EQ(from_grown.results[r].first_frame, from_built.results[r].first_frame);
      EXPECT_NEAR(from_grown.results[r].score, from_built.results[r].score, 1e-6);
    }
  }
  EXPECT_THAT(grown->WithClips({clips[2]}).status().message(), HasSubstr("already"));
  LibraryClip wrong = clips[2];
  wrong.clip_id = 99;
  wrong.coordinates = RowMatrixXf::Zero(5, kDims + 1);
  EXPECT_FALSE(grown->WithClips({wrong}).ok());
}

TEST_F(SearchTest, TreeMemoryIsSmallBesideTheCoordinates) {
  // The index reads coordinates in place: its own memory is below 2x the indexed float32s.
  const int64_t indexed_bytes = library_->total_frames() * library_->ann_dims() * 4;
  EXPECT_LT(library_->tree_bytes(), 2 * indexed_bytes);
  EXPECT_EQ(library_->coordinate_bytes(), library_->total_frames() * kDims * 4);
}

TEST_F(SearchTest, BuildRejectsBadLibraries) {
  EXPECT_FALSE(LibraryIndex::Build({}, 30.0, {}).ok());
  std::vector<LibraryClip> mixed;
  mixed.push_back({1, "a", {}, RowMatrixXf::Zero(10, 12)});
  mixed.push_back({2, "b", {}, RowMatrixXf::Zero(10, 11)});
  EXPECT_EQ(LibraryIndex::Build(std::move(mixed), 30.0, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  std::vector<LibraryClip> nan;
  nan.push_back({1, "a", {}, RowMatrixXf::Constant(10, 12, NAN)});
  EXPECT_FALSE(LibraryIndex::Build(std::move(nan), 30.0, {}).ok());
  std::vector<LibraryClip> narrow;
  narrow.push_back({1, "a", {}, RowMatrixXf::Zero(10, 4)});
  EXPECT_FALSE(LibraryIndex::Build(std::move(narrow), 30.0, {}).ok());
}

TEST_F(SearchTest, CharacteristicFrameIsTheFarthestFromTheNeutralPose) {
  // The pattern peaks in the middle; its ends are at the origin.
  EXPECT_NEAR(FindCharacteristicFrame(query(), 10, NeutralPose::kOrigin), 19.5, 3);
  EXPECT_NEAR(FindCharacteristicFrame(query(), 10, NeutralPose::kBoundaryMean), 19.5, 3);
  RowMatrixXf ramp(5, 2);
  ramp << 0, 0, 1, 0, 2, 0, 3, 0, 10, 0;
  EXPECT_EQ(FindCharacteristicFrame(CoordinateView::Of(ramp), 2, NeutralPose::kQueryMean), 4);
  EXPECT_EQ(FindCharacteristicFrame(CoordinateView::Of(ramp), 2, NeutralPose::kOrigin), 4);
}

// The second anchor: the farthest frame from the anchor's pose, at least a quarter of the query
// (and 2 frames) away, on either side; none in a query too short for one.
TEST(SecondAnchor, IsTheFarthestFrameAQuarterOfTheQueryAway) {
  RowMatrixXf line(12, 2);
  for (int f = 0; f < 12; ++f) line.row(f) << static_cast<float>(f == 5 ? 100 : f), 0;
  const CoordinateView q = CoordinateView::Of(line);
  EXPECT_EQ(FindSecondAnchor(q, 11, 2), 5);  // frame 5 is farthest from frame 11's pose
  EXPECT_EQ(FindSecondAnchor(q, 5, 2), 0);   // from frame 5's (100), frame 0 beats frame 8
  EXPECT_EQ(FindSecondAnchor(q, 3, 2), 11);  // frames 1..5 lie within 3 frames of frame 3
  EXPECT_EQ(FindSecondAnchor(q, 0, 1), 5);
  RowMatrixXf three(3, 2);
  three.setZero();
  EXPECT_EQ(FindSecondAnchor(CoordinateView::Of(three), 1, 2), -1);
  EXPECT_EQ(FindSecondAnchor(CoordinateView::Of(three), 0, 2), 2);
}

TEST_F(SearchTest, FastSearchFindsEveryPlantedCopyFirst) {
  SearchParams params;
  params.neighbours = 200;
  absl::StatusOr<SearchResponse> response = Search(*library_, query(), params);
  ASSERT_TRUE(response.ok()) << response.status();
  const std::vector<SearchResult>& results = response->results;
  ASSERT_GE(results.size(), planted_.size());
  const std::vector<SearchResult> top(results.begin(), results.begin() + planted_.size());
  for (const Planted& p : planted_) EXPECT_TRUE(Found(top, p)) << p.clip << ":" << p.first;
  EXPECT_LT(results[0].score, 0.05);
  for (size_t i = 1; i < results.size(); ++i) EXPECT_LE(results[i - 1].score, results[i].score);
  for (size_t i = 0; i < results.size(); ++i) {
    for (size_t j = 0; j < i; ++j) EXPECT_FALSE(Overlaps(results[i], results[j], 0.5));
  }
  const SearchStats& stats = response->stats;
  EXPECT_EQ(stats.seeds, 200);
  EXPECT_GT(stats.clusters, 0);
  EXPECT_LE(stats.clusters, stats.seeds);
  EXPECT_GT(stats.warps, 0);
  EXPECT_GE(stats.total_ms, stats.warps_ms);
  EXPECT_EQ(results[0].clip_name, "clip" + std::to_string(results[0].clip_index));
  EXPECT_NEAR(results[0].start_s, results[0].first_frame / 30.0, 1e-9);
}

// Unless a search says how many, the seeds follow the library's size: the thesis's 1000 up to
// 10 h of seed frames (540,000 at about 15 Hz), then 1000 more per tenfold.
TEST(SearchSeeds, FollowTheLibrarysSize) {
  const RowMatrixXf query = testing::Pattern(40, 5);
  SearchParams params;
  params.characteristic_frame = 20;
  for (const auto& [frames, seeds] :
       {std::pair<int64_t, int64_t>{3'000, 1000}, {1'080'000, 1000}, {1'200'000, 1046}}) {
    std::vector<LibraryClip> clips;
    for (int64_t first = 0; first < frames; first += 300'000) {
      clips.push_back({first,
                       "noise",
                       {},
                       testing::SmoothNoise(std::min<int64_t>(300'000, frames - first), 5, 3)});
    }
    const std::unique_ptr<LibraryIndex> library = *LibraryIndex::Build(std::move(clips), 30, {});
    ASSERT_EQ(library->tree_every(), 2);
    params.neighbours = 0;
    EXPECT_EQ(Search(*library, CoordinateView::Of(query), params)->stats.seeds, seeds) << frames;
    params.neighbours = 300;
    EXPECT_EQ(Search(*library, CoordinateView::Of(query), params)->stats.seeds, 300) << frames;
  }
}

TEST_F(SearchTest, PathsAreReturnedOnRequest) {
  SearchParams params;
  params.return_path = true;
  absl::StatusOr<SearchResponse> response = Search(*library_, query(), params);
  ASSERT_TRUE(response.ok());
  for (const SearchResult& r : response->results) {
    ASSERT_EQ(r.path.size(), 40u);
    EXPECT_EQ(r.path.front(), r.first_frame);
    EXPECT_EQ(r.path.back(), r.last_frame);
    EXPECT_EQ(r.path[response->stats.characteristic_frame], r.seed_frame);
  }
}

// Refinement frees each warp from its seed: scores only fall, the best result reaches the
// exact optimum, and a refined path still passes the characteristic row at the reported frame
// and has the reported score.
TEST_F(SearchTest, RefinementOnlyImprovesAndKeepsPathsTrue) {
  // The characteristic row is the pattern's row 24, so the seeds sit 4 frames late and the
  // anchored warps cannot follow the copies exactly.
  RowMatrixXf query = testing::Pattern(40, kDims);
  query.row(20) = testing::Pattern(40, kDims).row(24);
  const CoordinateView q = CoordinateView::Of(query);
  SearchParams params;
  params.characteristic_frame = 20;
  params.neighbours = 200;
  params.return_path = true;
  params.refine = false;
  const SearchResponse anchored = *Search(*library_, q, params);
  params.refine = true;
  const SearchResponse refined = *Search(*library_, q, params);
  const SearchResponse exact = *ExactSearch(*library_, q, params);
  ASSERT_FALSE(refined.results.empty());
  EXPECT_LT(refined.results[0].score, anchored.results[0].score);
  EXPECT_NEAR(refined.results[0].score, exact.results[0].score, 1e-5);
  const int anchor = refined.stats.characteristic_frame;
  for (const SearchResult& r : refined.results) {
    ASSERT_EQ(r.path.size(), 40u);
    EXPECT_EQ(r.path.front(), r.first_frame);
    EXPECT_EQ(r.path.back(), r.last_frame);
    EXPECT_EQ(r.path[anchor], r.seed_frame);
    EXPECT_NEAR(r.start_s, r.first_frame / 30.0, 1e-9);
    EXPECT_NEAR(r.end_s, r.last_frame / 30.0, 1e-9);
    const CoordinateView clip = library_->clip_coordinates(r.clip_index);
    double sum = 0;
    int pauses = 0;
    for (int i = 0; i < 40; ++i) {
      if (i > 0) {
        EXPECT_GE(r.path[i] - r.path[i - 1], 0);
        EXPECT_LE(r.path[i] - r.path[i - 1], params.slope_limit);
        pauses = r.path[i] == r.path[i - 1] ? pauses + 1 : 0;
        // Refined paths are whole warps of the model; anchored ones pause once more at the seed.
        EXPECT_LE(pauses, params.slope_limit - (r.path[anchor] == r.path[i] ? 0 : 1));
      }
      sum += Distance(query.row(i).data(), clip.row(r.path[i]), params.dtw_dims);
    }
    EXPECT_NEAR(sum / 40, r.score, 1e-5);
  }
}

// A query of two actions, A then its mirror image -A, whose first action's pose is common: 60
// clips hold A exactly, then noise; one clip holds a weaker A (0.8 A) then -A, and matches best.
// The nearest frames to A's peak all lie in the 60, each a cluster of its own, so one anchor
// never reaches the true clip; a second anchor at -A's peak does, and the result passes the
// characteristic frame where its seed_frame says, with or without refinement.
TEST(SearchSecondAnchor, ReachesWhatACommonPoseHides) {
  const RowMatrixXf a = testing::Pattern(20, kDims);
  RowMatrixXf query(40, kDims);
  query << a, -a;
  std::vector<LibraryClip> clips;
  for (int c = 0; c <= 60; ++c) {
    RowMatrixXf curve = testing::SmoothNoise(200, kDims, 50 + c);
    if (c == 60) {
      RowMatrixXf weak(40, kDims);
      weak << 0.8f * a, -a;
      testing::Plant(curve, weak, 100);
    } else {
      testing::Plant(curve, a, 60 + c);
    }
    clips.push_back({c, "clip" + std::to_string(c), {}, std::move(curve)});
  }
  const std::unique_ptr<LibraryIndex> library = *LibraryIndex::Build(std::move(clips), 30.0, {});
  const CoordinateView q = CoordinateView::Of(query);
  SearchParams params;
  params.characteristic_frame = 10;
  params.neighbours = 40;
  params.max_results = 5;
  const SearchResponse exact = *ExactSearch(*library, q, params);
  ASSERT_FALSE(exact.results.empty());
  ASSERT_EQ(exact.results[0].clip_id, 60);

  params.second_anchor_scatter = 0;
  const SearchResponse one = *Search(*library, q, params);
  EXPECT_EQ(one.stats.second_anchor, -1);
  // The seeds scatter: past the default share.
  EXPECT_GT(one.stats.clusters, SearchParams().second_anchor_scatter * one.stats.seeds);
  for (const SearchResult& r : one.results) EXPECT_NE(r.clip_id, 60);

  params.second_anchor_scatter = SearchParams().second_anchor_scatter;
  params.return_path = true;
  for (const bool refine : {true, false}) {
    params.refine = refine;
    const SearchResponse two = *Search(*library, q, params);
    EXPECT_THAT(two.stats.second_anchor, ::testing::AllOf(::testing::Ge(25), ::testing::Le(34)))
        << refine;                                            // -A's peak
    EXPECT_EQ(two.stats.seeds, params.neighbours) << refine;  // half at each anchor
    ASSERT_FALSE(two.results.empty());
    EXPECT_EQ(two.results[0].clip_id, 60) << refine;
    if (refine) {
      EXPECT_NEAR(two.results[0].score, exact.results[0].score, 1e-5);
    }
    for (const SearchResult& r : two.results) {
      ASSERT_EQ(r.path.size(), 40u);
      EXPECT_EQ(r.path[10], r.seed_frame) << refine;
    }
  }
  // Below the share, from one seed, or with several points, there is no second anchor.
  params.second_anchor_scatter = 1;
  EXPECT_EQ(Search(*library, q, params)->stats.second_anchor, -1);
  params.second_anchor_scatter = 0.5;
  params.neighbours = 1;
  const SearchResponse single = *Search(*library, q, params);
  EXPECT_EQ(single.stats.second_anchor, -1);
  EXPECT_EQ(single.stats.seeds, 1);
  EXPECT_FALSE(single.results.empty());
  params.neighbours = 40;
  params.characteristic_frame = -1;
  params.characteristic_frames = {10, 30};
  EXPECT_EQ(Search(*library, q, params)->stats.second_anchor, -1);
}

TEST_F(SearchTest, FiltersByClipIdAndTag) {
  SearchParams params;
  params.clip_ids = {101};
  absl::StatusOr<SearchResponse> by_id = Search(*library_, query(), params);
  ASSERT_TRUE(by_id.ok());
  ASSERT_FALSE(by_id->results.empty());
  for (const SearchResult& r : by_id->results) EXPECT_EQ(r.clip_id, 101);
  params.clip_ids.clear();
  params.tags = {"walk"};
  absl::StatusOr<SearchResponse> by_tag = Search(*library_, query(), params);
  ASSERT_TRUE(by_tag.ok());
  for (const SearchResult& r : by_tag->results) EXPECT_NE(r.clip_id, 101);
  params.tags = {"nothing-has-this"};
  EXPECT_TRUE(Search(*library_, query(), params)->results.empty());
  params.tags.clear();
  params.clip_ids = {999};
  EXPECT_EQ(Search(*library_, query(), params).status().code(), absl::StatusCode::kNotFound);
}

// The excluded range is left out inside the search, before the ranking: no result overlaps it,
// and the search still fills max_results with the others, in one run of each kind of search.
TEST_F(SearchTest, AnExcludedRangeIsLeftOutAndTheResultsStillFill) {
  const Planted& own = planted_.front();  // the copy a stored query of it would find first
  SearchParams params;
  params.max_results = 12;
  params.excluded = ExcludedRange{100, own.first, own.last};
  const auto overlaps = [&](const SearchResult& r) {
    return r.clip_id == 100 && r.first_frame <= own.last && r.last_frame >= own.first;
  };
  const RowMatrixXf pose = testing::Pattern(40, kDims).row(20);
  const RowMatrixXf two_actions = [&] {
    RowMatrixXf rows(80, kDims);
    rows << query_, query_;
    return rows;
  }();
  for (const char* kind : {"fast", "exact", "pose", "two points"}) {
    SCOPED_TRACE(kind);
    SearchParams searched = params;
    if (std::string(kind) == "two points") searched.characteristic_frames = {20, 60};
    const RowMatrixXf& rows = std::string(kind) == "pose"         ? pose
                              : std::string(kind) == "two points" ? two_actions
                                                                  : query_;
    const absl::StatusOr<SearchResponse> found =
        std::string(kind) == "exact" ? ExactSearch(*library_, CoordinateView::Of(rows), searched)
                                     : Search(*library_, CoordinateView::Of(rows), searched);
    ASSERT_TRUE(found.ok()) << found.status();
    // Chains of two parts are as many as the library holds.
    if (std::string(kind) != "two points") {
      EXPECT_EQ(found->results.size(), 12u);
    }
    EXPECT_FALSE(found->results.empty());
    EXPECT_TRUE(std::none_of(found->results.begin(), found->results.end(), overlaps));
    // Without it, the range's copy is found.
    searched.excluded.reset();
    const absl::StatusOr<SearchResponse> all =
        std::string(kind) == "exact" ? ExactSearch(*library_, CoordinateView::Of(rows), searched)
                                     : Search(*library_, CoordinateView::Of(rows), searched);
    ASSERT_TRUE(all.ok()) << all.status();
    EXPECT_TRUE(std::any_of(all->results.begin(), all->results.end(), overlaps));
  }
  // A range between two frames (last = first - 1) leaves out what spans the gap; a reversed one
  // is refused.
  params.excluded = ExcludedRange{100, own.first + 5, own.first + 4};
  const absl::StatusOr<SearchResponse> gap = Search(*library_, query(), params);
  ASSERT_TRUE(gap.ok()) << gap.status();
  for (const SearchResult& r : gap->results) {
    EXPECT_FALSE(r.clip_id == 100 && r.first_frame <= own.first + 4 &&
                 r.last_frame >= own.first + 5);
  }
  params.excluded = ExcludedRange{100, own.first + 5, own.first + 3};
  EXPECT_EQ(Search(*library_, query(), params).status().code(), absl::StatusCode::kInvalidArgument);
}

// Takes of one motion, as a stored take's range searches them: the take (id 1), its exact copy
// (id 2) and 14 near copies, each with a little noise of its own.
std::unique_ptr<LibraryIndex> TakesAndACopy(int take_frames) {
  const RowMatrixXf take = testing::Pattern(take_frames, kDims);
  std::vector<LibraryClip> clips = {{1, "take", {}, take}, {2, "copy", {}, take}};
  for (int k = 0; k < 14; ++k) {
    RowMatrixXf near = testing::Pattern(take_frames + k % 3, kDims);
    near += 0.05f * testing::SmoothNoise(near.rows(), kDims, 300 + k);
    clips.push_back({3 + k, "near", {}, std::move(near)});
  }
  return *LibraryIndex::Build(std::move(clips), 30.0, {});
}

// A whole take searched with itself excluded finds its exact copy first, scored 0, whether the
// copy starts an even or an odd number of frames after it. The kd-tree holds every other frame
// at 30 Hz, and the warps run on every other frame from their seed: a copy an odd number of
// frames along had seeds one frame off the query's, was warped a frame out of step at every
// sample, and ranked below a pool of near copies that refinement never looked past
// (bench/notes/2026-12-07-copy-miss.md).
TEST(SearchExcludedQuery, FindsTheTakesExactCopyFirstWhateverItsPhase) {
  for (const int take_frames : {50, 51, 52, 53}) {
    SCOPED_TRACE(take_frames);
    const std::unique_ptr<LibraryIndex> library = TakesAndACopy(take_frames);
    const CoordinateView take = library->clip_coordinates(0);
    SearchParams params;
    params.max_results = 1;
    params.excluded = ExcludedRange{1, 0, take_frames - 1};
    for (const bool exact : {false, true}) {
      SCOPED_TRACE(exact ? "exact" : "fast");
      const absl::StatusOr<SearchResponse> found =
          exact ? ExactSearch(*library, take, params) : Search(*library, take, params);
      ASSERT_TRUE(found.ok()) << found.status();
      ASSERT_EQ(found->results.size(), 1u);
      EXPECT_EQ(found->results[0].clip_id, 2);
      EXPECT_NEAR(found->results[0].score, 0.0, 1e-6);
    }
  }
}

// Every take of such libraries searched whole, itself excluded: the fast search's best is the
// exact search's, each take's copy or near copies alike (which
// ExactSearch.MatchesAnExhaustiveReferenceOnSmallLibraries checks against brute force).
TEST(SearchExcludedQuery, EveryTakesBestIsTheExactSearchsBest) {
  for (const int take_frames : {51, 52}) {
    const std::unique_ptr<LibraryIndex> library = TakesAndACopy(take_frames);
    for (int c = 0; c < library->clip_count(); ++c) {
      SCOPED_TRACE(::testing::Message() << take_frames << " frames, clip " << c);
      const CoordinateView query = library->clip_coordinates(c);
      SearchParams params;
      params.max_results = 1;  // the smallest pool of candidates refined (12)
      params.excluded = ExcludedRange{library->clip(c).clip_id, 0, query.rows - 1};
      const absl::StatusOr<SearchResponse> fast = Search(*library, query, params);
      const absl::StatusOr<SearchResponse> exact = ExactSearch(*library, query, params);
      ASSERT_TRUE(fast.ok()) << fast.status();
      ASSERT_TRUE(exact.ok()) << exact.status();
      ASSERT_FALSE(fast->results.empty());
      ASSERT_FALSE(exact->results.empty());
      EXPECT_EQ(fast->results[0].clip_id, exact->results[0].clip_id);
      EXPECT_NEAR(fast->results[0].score, exact->results[0].score, 1e-5);
    }
  }
}

// A one-frame query: the nearest distinct places, one frame each, scored by the pose distance.
TEST_F(SearchTest, OneFrameIsAPoseQuery) {
  // The pattern's peak: each planted copy holds it near its middle.
  const RowMatrixXf pattern = testing::Pattern(40, kDims);
  const RowMatrixXf pose = pattern.row(20);
  SearchParams params;
  params.max_results = 10;
  absl::StatusOr<SearchResponse> found = Search(*library_, CoordinateView::Of(pose), params);
  ASSERT_TRUE(found.ok()) << found.status();
  const std::vector<SearchResult>& results = found->results;
  ASSERT_EQ(results.size(), 10u);
  // The global nearest frame over the warp's dimensions, by brute force, comes first.
  double nearest = INFINITY;
  for (int64_t f = 0; f < library_->total_frames(); ++f) {
    nearest = std::min<double>(nearest, Distance(pose.data(), FrameRow(*library_, f), 5));
  }
  EXPECT_NEAR(results[0].score, nearest, 1e-6);
  const int64_t separation = std::llround(kPoseSeparationS * library_->rate());
  for (size_t i = 0; i < results.size(); ++i) {
    const SearchResult& r = results[i];
    EXPECT_EQ(r.first_frame, r.seed_frame);
    EXPECT_EQ(r.last_frame, r.seed_frame);
    EXPECT_DOUBLE_EQ(r.start_s, r.seed_frame / 30.0);
    const CoordinateView clip = library_->clip_coordinates(r.clip_index);
    EXPECT_FLOAT_EQ(r.score, Distance(pose.data(), clip.row(r.seed_frame), 5));
    if (i > 0) {
      EXPECT_LE(results[i - 1].score, r.score);
    }
    for (size_t j = 0; j < i; ++j) {
      if (results[j].clip_index == r.clip_index) {
        EXPECT_GE(std::abs(results[j].seed_frame - r.seed_frame), separation) << i << " " << j;
      }
    }
  }
  // Every planted copy is among the first three: the peak is far from the noise.
  for (const Planted& p : planted_) {
    EXPECT_TRUE(std::any_of(results.begin(), results.begin() + 3,
                            [&](const SearchResult& r) {
                              return r.clip_index == p.clip && r.seed_frame >= p.first &&
                                     r.seed_frame <= p.last;
                            }))
        << "clip " << p.clip << " at " << p.first;
  }
  // Paths only when asked, then each the one frame (it had none, so that explaining a pose
  // query answered INTERNAL: found by the search_request fuzzer).
  for (const SearchResult& r : results) EXPECT_TRUE(r.path.empty());
  params.return_path = true;
  found = Search(*library_, CoordinateView::Of(pose), params);
  ASSERT_TRUE(found.ok()) << found.status();
  ASSERT_EQ(found->results.size(), results.size());
  for (const SearchResult& r : found->results)
    EXPECT_EQ(r.path, std::vector<int64_t>{r.seed_frame});
  params.return_path = false;
  // A library frame finds itself at distance 0; the filters hold.
  const RowMatrixXf own = Eigen::Map<const RowMatrixXf>(FrameRow(*library_, 1200 + 77), 1, kDims);
  params.clip_ids = {101};
  found = Search(*library_, CoordinateView::Of(own), params);
  ASSERT_TRUE(found.ok()) << found.status();
  ASSERT_FALSE(found->results.empty());
  EXPECT_EQ(found->results[0].seed_frame, 77);
  EXPECT_EQ(found->results[0].score, 0.0);
  for (const SearchResult& r : found->results) EXPECT_EQ(r.clip_id, 101);
}

TEST_F(SearchTest, RejectsBadParametersAndQueries) {
  const auto code = [&](auto change) {
    SearchParams params;
    change(params);
    return Search(*library_, query(), params).status().code();
  };
  const auto bad = absl::StatusCode::kInvalidArgument;
  EXPECT_EQ(code([](SearchParams& p) { p.ann_dims = 0; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.ann_dims = 13; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.dtw_dims = 99; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.neighbours = -1; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.neighbours = 100'000'000; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.epsilon = -1; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.epsilon = NAN; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.slope_limit = 0; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.slope_limit = 9; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.max_results = 0; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.characteristic_frame = 40; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.cluster_gap_s = -1; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.max_overlap = 2; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.second_anchor_scatter = -0.1; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.second_anchor_scatter = 1.5; }), bad);
  EXPECT_EQ(code([](SearchParams& p) { p.second_anchor_scatter = NAN; }), bad);
  RowMatrixXf nan = query_;
  nan(3, 2) = NAN;
  EXPECT_EQ(Search(*library_, CoordinateView::Of(nan), {}).status().code(), bad);
  const RowMatrixXf narrow = query_.leftCols(8);
  absl::StatusOr<SearchResponse> narrow_result = Search(*library_, CoordinateView::Of(narrow), {});
  EXPECT_EQ(narrow_result.status().code(), bad);
  EXPECT_THAT(std::string(narrow_result.status().message()), HasSubstr("dimensions"));
  EXPECT_EQ(Search(*library_, CoordinateView{query_.data(), 0, kDims}, {}).status().code(), bad);
}

TEST_F(SearchTest, StopsWhenTheCallerSaysSo) {
  SearchParams params;
  params.should_stop = [] { return true; };
  EXPECT_EQ(Search(*library_, query(), params).status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(ExactSearch(*library_, query(), params).status().code(), absl::StatusCode::kCancelled);
}

TEST_F(SearchTest, ConcurrentSearchesAgree) {
  const SearchResponse reference = *Search(*library_, query(), {});
  std::atomic<int> mismatches = 0;
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 20; ++i) {
        absl::StatusOr<SearchResponse> r = Search(*library_, query(), {});
        if (!r.ok() || r->results.size() != reference.results.size() ||
            r->results[0].first_frame != reference.results[0].first_frame) {
          ++mismatches;
        }
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(mismatches, 0);
}

// The subsequence-DTW definition of a match, by brute force over every start: for each clip
// frame, the best warp ending there (over all starts); then ranked with overlap suppression.
std::vector<SearchResult> ExhaustiveReference(const LibraryIndex& library, const RowMatrixXf& q,
                                              int s, int dims, int k) {
  std::vector<SearchResult> candidates;
  for (int c = 0; c < library.clip_count(); ++c) {
    const CoordinateView x = library.clip_coordinates(c);
    std::vector<SearchResult> best_ending_at(x.rows);
    for (SearchResult& r : best_ending_at) r.score = INFINITY;
    for (int64_t start = 0; start < x.rows; ++start) {
      // best[j][z]: best cost with the current query row on clip frame start + j.
      const int64_t width = std::min<int64_t>(x.rows - start, s * (q.rows() - 1) + 1);
      std::vector<std::vector<double>> best(width, std::vector<double>(s, INFINITY));
      best[0][0] = Distance(q.row(0).data(), x.row(start), dims);
      for (int i = 1; i < q.rows(); ++i) {
        std::vector<std::vector<double>> next(width, std::vector<double>(s, INFINITY));
        for (int64_t j = 0; j < width; ++j) {
          for (int z = 0; z < s; ++z) {
            if (!std::isfinite(best[j][z])) continue;
            for (int advance = 0; advance <= s; ++advance) {
              const int nz = advance == 0 ? z + 1 : 0;
              if (nz > s - 1 || j + advance >= width) continue;
              const double c2 =
                  best[j][z] + Distance(q.row(i).data(), x.row(start + j + advance), dims);
              next[j + advance][nz] = std::min(next[j + advance][nz], c2);
            }
          }
        }
        best.swap(next);
      }
      for (int64_t j = 0; j < width; ++j) {
        const double total = *std::min_element(best[j].begin(), best[j].end());
        if (!std::isfinite(total)) continue;
        SearchResult& r = best_ending_at[start + j];
        if (total / q.rows() < r.score) {
          r.clip_index = c;
          r.first_frame = start;
          r.last_frame = start + j;
          r.score = total / q.rows();
        }
      }
    }
    for (const SearchResult& r : best_ending_at) {
      if (std::isfinite(r.score)) candidates.push_back(r);
    }
  }
  return RankResults(std::move(candidates), 0.5, k);
}

// `result.path` is a warp of `query` within the slope limit `s`, from its first frame to its
// last, whose mean distance over `dims` dimensions is its score.
void ExpectPathOfItsScore(const LibraryIndex& library, CoordinateView query,
                          const SearchResult& result, int s, int dims) {
  ASSERT_EQ(static_cast<int64_t>(result.path.size()), query.rows);
  EXPECT_EQ(result.path.front(), result.first_frame);
  EXPECT_EQ(result.path.back(), result.last_frame);
  const CoordinateView clip = library.clip_coordinates(result.clip_index);
  double total = Distance(query.row(0), clip.row(result.path[0]), dims);
  int pauses = 0;
  for (size_t i = 1; i < result.path.size(); ++i) {
    const int64_t step = result.path[i] - result.path[i - 1];
    EXPECT_GE(step, 0);
    EXPECT_LE(step, s);
    pauses = step == 0 ? pauses + 1 : 0;
    EXPECT_LE(pauses, s - 1);
    total += Distance(query.row(i), clip.row(result.path[i]), dims);
  }
  EXPECT_NEAR(total / query.rows, result.score, 1e-5 * (1 + result.score));
}

TEST(ExactSearch, MatchesAnExhaustiveReferenceOnSmallLibraries) {
  for (int trial = 0; trial < 6; ++trial) {
    const int s = 1 + trial % 3;
    std::vector<LibraryClip> clips;
    for (int c = 0; c < 2; ++c) {
      clips.push_back({c, "c", {}, testing::SmoothNoise(90 + 13 * c, 4, 50 + 7 * trial + c)});
    }
    const std::unique_ptr<LibraryIndex> library =
        *LibraryIndex::Build(std::move(clips), 30, {4, 8});
    const RowMatrixXf q = testing::SmoothNoise(7, 4, 900 + trial);
    SearchParams params;
    params.slope_limit = s;
    params.dtw_dims = 4;
    params.ann_dims = 4;
    params.max_results = 5;
    absl::StatusOr<SearchResponse> exact = ExactSearch(*library, CoordinateView::Of(q), params);
    ASSERT_TRUE(exact.ok()) << exact.status();
    const std::vector<SearchResult> reference = ExhaustiveReference(*library, q, s, 4, 5);
    ASSERT_EQ(exact->results.size(), reference.size()) << "trial " << trial;
    // The best match is exactly the global optimum; the rest agree in score.
    EXPECT_NEAR(exact->results[0].score, reference[0].score, 1e-5) << "trial " << trial;
    for (size_t i = 0; i < reference.size(); ++i) {
      EXPECT_NEAR(exact->results[i].score, reference[i].score, 1e-4)
          << "trial " << trial << " #" << i;
      EXPECT_TRUE(exact->results[i].path.empty());
    }
    // With their paths when asked: the same results, each path scoring its result.
    params.return_path = true;
    absl::StatusOr<SearchResponse> with_paths =
        ExactSearch(*library, CoordinateView::Of(q), params);
    ASSERT_TRUE(with_paths.ok()) << with_paths.status();
    ASSERT_EQ(with_paths->results.size(), reference.size());
    for (size_t i = 0; i < reference.size(); ++i) {
      SCOPED_TRACE(::testing::Message() << "trial " << trial << " #" << i);
      EXPECT_EQ(with_paths->results[i].score, exact->results[i].score);
      EXPECT_EQ(with_paths->results[i].last_frame, exact->results[i].last_frame);
      ExpectPathOfItsScore(*library, CoordinateView::Of(q), with_paths->results[i], s, 4);
    }
  }
}

TEST_F(SearchTest, ExactSearchFindsThePlantedCopiesAndPrunes) {
  SearchParams params;
  params.max_results = 3;
  // On one thread, clips are scanned in order, each pruned by the ones before: on several,
  // how much is pruned depends on which clip finishes first (the results do not).
  params.exact_threads = 1;
  absl::StatusOr<SearchResponse> exact = ExactSearch(*library_, query(), params);
  ASSERT_TRUE(exact.ok()) << exact.status();
  ASSERT_EQ(exact->results.size(), 3u);
  for (const Planted& p : planted_) EXPECT_TRUE(Found(exact->results, p)) << p.first;
  EXPECT_GT(exact->stats.pruned_blocks, 0);
  EXPECT_LT(exact->stats.cells, library_->total_frames() * query_.rows() / 2)
      << "early abandoning should skip most cells";
}

TEST_F(SearchTest, ExactSearchTimesItsWarpsInsideTheTotal) {
  absl::StatusOr<SearchResponse> exact = ExactSearch(*library_, query(), SearchParams());
  ASSERT_TRUE(exact.ok()) << exact.status();
  const SearchStats& stats = exact->stats;
  EXPECT_GT(stats.warps_ms, 0);
  // The total adds the query's checks and the ranking, which the warps' time leaves out.
  EXPECT_LT(stats.warps_ms, stats.total_ms);
  EXPECT_EQ(stats.seeds_ms, 0);
  EXPECT_EQ(stats.refine_ms, 0);
}

TEST(SearchRecall, FastSearchFindsWhatExactSearchFinds) {
  // Eight copies of the pattern at speeds 0.75x to 1.4x among noise: exact search ranks them
  // first, and the fast search must find every one of them; at 30 Hz, and at 120 Hz (the same
  // motion four times as finely sampled), where the seeds and warps run at 30 Hz and the results
  // are settled at the full rate: whole warps of the model, with the scores they report.
  for (const int scale : {1, 4}) {
    SCOPED_TRACE(scale);
    std::vector<LibraryClip> clips;
    std::vector<Planted> planted;
    const std::vector<int> lengths = {30, 34, 38, 40, 44, 48, 52, 56};
    for (int c = 0; c < 4; ++c) {
      RowMatrixXf curve = testing::SmoothNoise(900 * scale, kDims, 70 + c);
      for (int k = 0; k < 2; ++k) {
        const int frames = lengths[2 * c + k] * scale, at = (150 + 400 * k) * scale;
        testing::Plant(curve, testing::Pattern(frames, kDims), at);
        planted.push_back({c, at, at + frames - 1});
      }
      clips.push_back({c, "clip", {}, std::move(curve)});
    }
    const std::unique_ptr<LibraryIndex> library =
        *LibraryIndex::Build(std::move(clips), 30 * scale, {});
    const RowMatrixXf query = testing::Pattern(40 * scale, kDims);
    SearchParams params;
    params.max_results = 8;
    params.return_path = true;
    const SearchResponse exact = *ExactSearch(*library, CoordinateView::Of(query), params);
    const SearchResponse fast = *Search(*library, CoordinateView::Of(query), params);
    ASSERT_EQ(exact.results.size(), 8u);
    for (const Planted& p : planted) {
      EXPECT_TRUE(SearchTest::Found(exact.results, p)) << p.clip << ":" << p.first;
      EXPECT_TRUE(SearchTest::Found(fast.results, p)) << p.clip << ":" << p.first;
    }
    for (const SearchResult& r : fast.results) {
      ASSERT_EQ(r.path.size(), static_cast<size_t>(query.rows()));
      EXPECT_EQ(r.path.front(), r.first_frame);
      EXPECT_EQ(r.path.back(), r.last_frame);
      for (size_t i = 1; i < r.path.size(); ++i) {
        EXPECT_GE(r.path[i] - r.path[i - 1], 0);
        EXPECT_LE(r.path[i] - r.path[i - 1], params.slope_limit);
      }
      EXPECT_NEAR(testing::MeanPathDistance(query, library->CopyClipCoordinates(r.clip_index),
                                            r.path, params.dtw_dims),
                  r.score, 1e-5);
    }
  }
}

// At 120 Hz the warps run at 15 Hz and the best are settled at the full rate, where two of
// them can converge on one place: the fast search still returns as many results as the exact
// search. Libraries where it returned one fewer before (noise seeds found by a sweep).
TEST(SearchRecall, FillsMaxResultsWhereTheExactSearchDoes) {
  for (const int seed : {15, 50, 59}) {
    std::vector<LibraryClip> clips;
    for (int c = 0; c < 3; ++c) {
      RowMatrixXf curve = testing::SmoothNoise(1600, kDims, 1000 + seed * 7 + c);
      for (int k = 0; k < 3; ++k) {
        const int frames = (30 + 6 * k + 3 * c + seed % 5) * 4;
        testing::Plant(curve, testing::Pattern(frames, kDims), 100 + 500 * k);
      }
      clips.push_back({c, "clip", {}, std::move(curve)});
    }
    const std::unique_ptr<LibraryIndex> library = *LibraryIndex::Build(std::move(clips), 120, {});
    const RowMatrixXf query = testing::Pattern(160, kDims);
    for (const int max_results : {12, 15, 20}) {
      SCOPED_TRACE(::testing::Message() << "seed " << seed << ", max_results " << max_results);
      SearchParams params;
      params.max_results = max_results;
      const SearchResponse exact = *ExactSearch(*library, CoordinateView::Of(query), params);
      const SearchResponse fast = *Search(*library, CoordinateView::Of(query), params);
      ASSERT_EQ(exact.results.size(), static_cast<size_t>(max_results));
      EXPECT_EQ(fast.results.size(), exact.results.size());
    }
  }
}

// The kept set of the streaming top results, as it was kept before the per-clip grouping: one
// vector in the order offered, every offer compared with every kept result, in the ranking's
// order (RanksBefore: ties by clip and frames, as RankResults breaks them).
std::vector<SearchResult> ReferenceTop(const std::vector<SearchResult>& offers, int k,
                                       double max_overlap) {
  std::vector<SearchResult> kept;
  for (const SearchResult& candidate : offers) {
    if (static_cast<int>(kept.size()) == k &&
        !RanksBefore(candidate, *std::max_element(kept.begin(), kept.end(), RanksBefore))) {
      continue;
    }
    if (std::any_of(kept.begin(), kept.end(), [&](const SearchResult& other) {
          return !RanksBefore(candidate, other) && Overlaps(candidate, other, max_overlap);
        })) {
      continue;
    }
    std::erase_if(kept, [&](const SearchResult& other) {
      return RanksBefore(candidate, other) && Overlaps(other, candidate, max_overlap);
    });
    kept.push_back(candidate);
    if (static_cast<int>(kept.size()) > k) {
      kept.erase(std::max_element(kept.begin(), kept.end(), RanksBefore));
    }
  }
  return kept;
}

// Random offers with overlaps and tied scores: the same kept results, in the same order, and
// the same threshold after every offer; RankResults keeps every one of them.
TEST(StreamingTopResults, KeepsWhatOneOrderedListKeeps) {
  std::mt19937 random(7);
  for (int round = 0; round < 100; ++round) {
    const int k = 1 + static_cast<int>(random() % 40);
    const int clips = 1 + static_cast<int>(random() % 6);
    // Clip ids in another order than the indices: ties go by id.
    std::vector<int64_t> ids(clips);
    for (int c = 0; c < clips; ++c) ids[c] = 100 + c;
    std::shuffle(ids.begin(), ids.end(), random);
    std::vector<SearchResult> offers;
    StreamingTopResults top(k, 0.5, 10);
    for (int i = 0; i < 200; ++i) {
      SearchResult& offer = offers.emplace_back();
      offer.clip_index = static_cast<int>(random() % clips);
      offer.clip_id = ids[offer.clip_index];
      offer.first_frame = static_cast<int64_t>(random() % 400);
      offer.last_frame = offer.first_frame + 5 + static_cast<int64_t>(random() % 30);
      offer.score = static_cast<double>(random() % 50) / 8;  // many ties
      top.Offer(offer);
      const std::vector<SearchResult> reference = ReferenceTop(offers, k, 0.5);
      const float expected =
          static_cast<int>(reference.size()) < k
              ? std::numeric_limits<float>::infinity()
              : static_cast<float>(10 * std::max_element(reference.begin(), reference.end(),
                                                         [](const auto& a, const auto& b) {
                                                           return a.score < b.score;
                                                         })
                                            ->score);
      ASSERT_EQ(top.threshold(), expected) << "round " << round << ", offer " << i;
    }
    const std::vector<SearchResult> kept = top.Take();
    const std::vector<SearchResult> reference = ReferenceTop(offers, k, 0.5);
    ASSERT_EQ(kept.size(), reference.size()) << "round " << round;
    EXPECT_EQ(RankedCount(kept, 0.5, k), static_cast<int>(kept.size())) << "round " << round;
    for (size_t i = 0; i < kept.size(); ++i) {
      EXPECT_EQ(
          std::tie(kept[i].clip_index, kept[i].first_frame, kept[i].last_frame, kept[i].score),
          std::tie(reference[i].clip_index, reference[i].first_frame, reference[i].last_frame,
                   reference[i].score))
          << "round " << round << ", result " << i;
    }
    EXPECT_TRUE(top.Take().empty());
  }
}

}  // namespace
}  // namespace motiondb
