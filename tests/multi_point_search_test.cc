// The search through several characteristic points (thesis 7.2.3) on projected libraries of
// compound motions: "A, a held pose, B" against "B then A", "A then C" and A alone, with holds
// of 0.3-5 s that one slope-limited warp through one point cannot absorb.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/characteristic_points.h"
#include "core/search/motion_search.h"
#include "tests/search_test_data.h"

namespace motiondb {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr int kDims = 5;
constexpr double kRate = 30.0;

enum Action { kA, kB, kC };

// One second of an action: a raise-and-return bump of height 3 in the action's own dimensions.
void AddAction(Action action, RowMatrixXf& curve, int64_t at) {
  for (int f = 0; f < 30; ++f) {
    const float bump = static_cast<float>(3.0 * std::pow(std::sin(std::numbers::pi * f / 29), 2));
    if (action == kA) curve.row(at + f).head(2).array() += bump;
    if (action == kB) curve.row(at + f).segment(2, 2).array() += bump;
    if (action == kC) curve(at + f, 4) += bump;
  }
}

// A second of rest, the first action, `hold_s` of rest, the second (if any), a second of rest;
// rest is the origin with a little smooth noise.
RowMatrixXf Compound(std::vector<Action> actions, double hold_s, uint32_t seed) {
  const int hold = static_cast<int>(std::lround(hold_s * kRate));
  const int64_t frames = 60 + 30 * static_cast<int64_t>(actions.size()) + hold;
  RowMatrixXf curve = 0.05f * testing::SmoothNoise(frames, kDims, seed);
  AddAction(actions[0], curve, 30);
  if (actions.size() > 1) AddAction(actions[1], curve, 60 + hold);
  return curve;
}

struct Kind {
  std::string name;
  std::vector<Action> actions;
};

constexpr double kHolds[] = {0.3, 1.0, 2.0, 3.5, 5.0};

class MultiPointSearchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::vector<Kind> kinds = {
        {"AB", {kA, kB}}, {"BA", {kB, kA}}, {"AC", {kA, kC}}, {"A", {kA}}};
    std::vector<LibraryClip> clips;
    for (const Kind& kind : kinds) {
      for (const double hold : kHolds) {
        const int64_t id = static_cast<int64_t>(clips.size()) + 1;
        clips.push_back({id, kind.name, {}, Compound(kind.actions, hold, 100 + id)});
      }
    }
    library_ = *LibraryIndex::Build(std::move(clips), kRate, {});
    query_ = Compound({kA, kB}, 0.3, 7);
  }

  SearchParams Params() const {
    SearchParams params;
    params.ann_dims = params.dtw_dims = kDims;
    params.max_results = 20;
    params.return_path = true;
    return params;
  }

  // The results' clip names in rank order.
  static std::vector<std::string> Names(const SearchResponse& response) {
    std::vector<std::string> names;
    for (const SearchResult& r : response.results) names.push_back(r.clip_name);
    return names;
  }
  // The share of the top five (the true instances' count) that are "AB" clips.
  static double PrecisionAt5(const SearchResponse& response) {
    const std::vector<std::string> names = Names(response);
    return std::count(names.begin(), names.begin() + std::min<size_t>(5, names.size()), "AB") / 5.0;
  }

  CoordinateView query() const { return CoordinateView::Of(query_); }

  std::unique_ptr<LibraryIndex> library_;
  RowMatrixXf query_;
};

TEST_F(MultiPointSearchTest, FindsTheTwoActionsAsTwoPoints) {
  const std::vector<int> frames =
      FindCharacteristicFrames(query(), kDims, NeutralPose::kQueryMean, 2);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_NEAR(frames[0], 30 + 14.5, 2);  // A's peak
  EXPECT_NEAR(frames[1], 69 + 14.5, 2);  // B's, after 9 frames of hold
  // One point: the pose farthest from the mean, one of the two peaks.
  const int one = FindCharacteristicFrame(query(), kDims, NeutralPose::kQueryMean);
  EXPECT_TRUE(std::abs(one - frames[0]) <= 2 || std::abs(one - frames[1]) <= 2) << one;
}

TEST_F(MultiPointSearchTest, RanksEveryAThenBAboveEveryOtherKind) {
  SearchParams params = Params();
  params.characteristic_points = 2;
  const absl::StatusOr<SearchResponse> several = Search(*library_, query(), params);
  ASSERT_TRUE(several.ok()) << several.status();
  EXPECT_EQ(PrecisionAt5(*several), 1.0) << ::testing::PrintToString(Names(*several));
  ASSERT_GT(several->results.size(), 5u);
  const double margin = several->results[5].score / several->results[4].score;
  EXPECT_GT(margin, 2.0);
  EXPECT_EQ(several->stats.characteristic_frames.size(), 2u);
  EXPECT_EQ(several->stats.characteristic_frame, several->stats.characteristic_frames[0]);

  // The thesis's one point, on the same library: the holds of 2 s and more do not fit one
  // slope-limited warp, so those instances fall behind A alone or A then C.
  params.characteristic_points = 1;
  const absl::StatusOr<SearchResponse> one = Search(*library_, query(), params);
  ASSERT_TRUE(one.ok()) << one.status();
  EXPECT_LT(PrecisionAt5(*one), 1.0) << ::testing::PrintToString(Names(*one));
}

// A, `hold_s` of rest, then a wave: 6 s of oscillation in B's dimensions (a long action whose
// point may lie anywhere in it), with a second of rest either side.
RowMatrixXf ThenWave(double hold_s, uint32_t seed) {
  const int hold = static_cast<int>(std::lround(hold_s * kRate));
  const int64_t frames = 60 + 30 + hold + 180;
  RowMatrixXf curve = 0.05f * testing::SmoothNoise(frames, kDims, seed);
  AddAction(kA, curve, 30);
  for (int f = 0; f < 180; ++f) {
    const float wave = static_cast<float>(1.5 * std::sin(2 * std::numbers::pi * f / 30.0) *
                                          std::sin(std::numbers::pi * f / 179));
    curve.row(60 + hold + f).segment(2, 2).array() += wave + 1.5f;
  }
  return curve;
}

TEST(MultiPointSearchHoldTest, AHoldLongerInTheQueryThanInTheClipIsAPause) {
  std::vector<LibraryClip> clips;
  for (const double hold : kHolds) {
    const int64_t id = static_cast<int64_t>(clips.size()) + 1;
    clips.push_back({id, "A then wave", {}, ThenWave(hold, 200 + id)});
  }
  for (const double hold : kHolds) {
    const int64_t id = static_cast<int64_t>(clips.size()) + 1;
    clips.push_back({id, "A then C", {}, Compound({kA, kC}, hold, 200 + id)});
  }
  const std::unique_ptr<LibraryIndex> library = *LibraryIndex::Build(std::move(clips), kRate, {});
  const RowMatrixXf query = ThenWave(5.0, 17);
  SearchParams params;
  params.ann_dims = params.dtw_dims = kDims;
  params.max_results = 10;
  params.return_path = true;
  params.characteristic_points = 2;
  const absl::StatusOr<SearchResponse> response =
      Search(*library, CoordinateView::Of(query), params);
  ASSERT_TRUE(response.ok()) << response.status();
  ASSERT_GE(response->results.size(), 5u);
  // Every instance matches as well whatever its hold: the one of 0.3 s scored 12.6 times the
  // best when the hold was split between the parts' warps.
  double best = INFINITY, worst = 0;
  for (int k = 0; k < 5; ++k) {
    const SearchResult& r = response->results[k];
    EXPECT_EQ(r.clip_name, "A then wave") << k;
    best = std::min(best, r.score);
    worst = std::max(worst, r.score);
  }
  EXPECT_LT(worst / best, 1.5);
  for (const SearchResult& r : response->results) {
    ASSERT_EQ(static_cast<int64_t>(r.path.size()), query.rows());
    EXPECT_TRUE(std::is_sorted(r.path.begin(), r.path.end()));
  }
}

TEST_F(MultiPointSearchTest, AResultsPathCoversTheQueryInOrderAndGivesItsScore) {
  // Two points found; points whose parts overlap in the clip; a part of one frame (a pose).
  for (const std::vector<int>& frames : {std::vector<int>{}, {44, 50, 84}, {0, 1, 84}}) {
    SearchParams params = Params();
    params.characteristic_points = 2;
    params.characteristic_frames = frames;
    const absl::StatusOr<SearchResponse> response = Search(*library_, query(), params);
    ASSERT_TRUE(response.ok()) << response.status();
    ASSERT_FALSE(response->results.empty());
    for (const SearchResult& r : response->results) {
      ASSERT_EQ(static_cast<int64_t>(r.path.size()), query_.rows());
      EXPECT_TRUE(std::is_sorted(r.path.begin(), r.path.end()));
      EXPECT_EQ(r.path.front(), r.first_frame);
      EXPECT_EQ(r.path.back(), r.last_frame);
      const CoordinateView clip = library_->clip_coordinates(r.clip_index);
      double sum = 0;
      for (int64_t i = 0; i < query_.rows(); ++i) {
        sum += Distance(query_.row(i).data(), clip.row(r.path[i]), kDims);
      }
      EXPECT_NEAR(r.score, sum / static_cast<double>(query_.rows()), 1e-4);
    }
  }
}

// The largest step of a result's path from one query row to the next.
int64_t LargestStep(const SearchResult& r) {
  int64_t step = 0;
  for (size_t i = 1; i < r.path.size(); ++i) step = std::max(step, r.path[i] - r.path[i - 1]);
  return step;
}

TEST_F(MultiPointSearchTest, APauseLongerThanTheGapBreaksTheChain) {
  SearchParams params = Params();
  params.characteristic_points = 2;
  absl::StatusOr<SearchResponse> response = Search(*library_, query(), params);
  ASSERT_TRUE(response.ok()) << response.status();
  // The 5 s hold, absorbed by a jump between the parts.
  const auto long_hold = std::find_if(response->results.begin(), response->results.end(),
                                      [](const SearchResult& r) { return r.clip_id == 5; });
  ASSERT_NE(long_hold, response->results.end());
  EXPECT_GT(LargestStep(*long_hold), 90);

  params.max_point_gap_s = 0.5;
  response = Search(*library_, query(), params);
  ASSERT_TRUE(response.ok()) << response.status();
  ASSERT_FALSE(response->results.empty());
  EXPECT_EQ(response->results[0].clip_id, 1);  // the query's own 0.3 s hold
  for (const SearchResult& r : response->results) {
    // 0.5 s at 30 Hz skipped: a step of 16 frames.
    EXPECT_LE(LargestStep(r), 16) << r.clip_name << " " << r.clip_id;
  }

  // No gap at all still chains parts whose matches follow one another.
  params.max_point_gap_s = 0;
  response = Search(*library_, query(), params);
  ASSERT_TRUE(response.ok()) << response.status();
  ASSERT_FALSE(response->results.empty());
  EXPECT_EQ(response->results[0].clip_id, 1);
  for (const SearchResult& r : response->results) EXPECT_LE(LargestStep(r), 2);
}

TEST_F(MultiPointSearchTest, GivenFramesAreTheAnchors) {
  SearchParams params = Params();
  params.characteristic_frames = {44, 84};
  const absl::StatusOr<SearchResponse> response = Search(*library_, query(), params);
  ASSERT_TRUE(response.ok()) << response.status();
  EXPECT_THAT(response->stats.characteristic_frames, ElementsAre(44, 84));
  EXPECT_EQ(PrecisionAt5(*response), 1.0);
}

TEST_F(MultiPointSearchTest, PointsFoundOnePerAction) {
  SearchParams params = Params();
  params.characteristic_points = 0;
  // A, a 0.3 s pause, B: two actions, each point at its peak.
  const std::vector<int> two = CharacteristicFrames(query(), kRate, params);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_NEAR(two[0], 30 + 14.5, 2);
  EXPECT_NEAR(two[1], 69 + 14.5, 2);
  // The same frames read at 10 Hz: a pause of 0.9 s, still two actions.
  EXPECT_EQ(CharacteristicFrames(query(), 10.0, params).size(), 2u);
  // Read at 120 Hz the dip (about 20 frames below the threshold) lasts under 0.2 s, shorter
  // than a pause between actions: one.
  EXPECT_EQ(CharacteristicFrames(query(), 120.0, params).size(), 1u);
  // One action, and two with a long pause.
  const RowMatrixXf one = Compound({kB}, 0, 3);
  EXPECT_EQ(CharacteristicFrames(CoordinateView::Of(one), kRate, params).size(), 1u);
  const RowMatrixXf apart = Compound({kA, kC}, 5.0, 3);
  EXPECT_EQ(CharacteristicFrames(CoordinateView::Of(apart), kRate, params).size(), 2u);
  // A query that never moves has no action: one point, and the search answers.
  const RowMatrixXf still = RowMatrixXf::Zero(60, kDims);
  EXPECT_EQ(CharacteristicFrames(CoordinateView::Of(still), kRate, params).size(), 1u);
  const absl::StatusOr<SearchResponse> found = Search(*library_, CoordinateView::Of(still), params);
  EXPECT_TRUE(found.ok()) << found.status();
  // A frame given wins.
  params.characteristic_frame = 40;
  EXPECT_THAT(CharacteristicFrames(query(), kRate, params), ElementsAre(40));
}

TEST_F(MultiPointSearchTest, BadPointsAreRefusedNamingTheField) {
  const auto message = [&](auto change) {
    SearchParams params = Params();
    change(params);
    const absl::StatusOr<SearchResponse> response = Search(*library_, query(), params);
    EXPECT_EQ(response.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(response.status().message());
  };
  EXPECT_THAT(message([](SearchParams& p) {
                p.characteristic_frames = {50, 40};
              }),
              HasSubstr("characteristic_frames[1] 40 does not follow"));
  EXPECT_THAT(message([](SearchParams& p) {
                p.characteristic_frames = {10, 500};
              }),
              HasSubstr("characteristic_frames[1] 500 is outside the query's frames 0-128"));
  EXPECT_THAT(message([](SearchParams& p) {
                p.characteristic_frames = {10, 50};
                p.characteristic_frame = 10;
              }),
              HasSubstr("give one"));
  EXPECT_THAT(message([](SearchParams& p) { p.characteristic_points = 17; }),
              HasSubstr("characteristic_points = 17 is out of range"));
  EXPECT_THAT(message([](SearchParams& p) { p.characteristic_frames.assign(17, 1); }),
              HasSubstr("at most 16"));
  EXPECT_THAT(message([](SearchParams& p) { p.max_point_gap_s = std::nan(""); }),
              HasSubstr("max_point_gap_s"));
}

}  // namespace
}  // namespace motiondb
