// A library split into disjoint parts (a cluster's logical shards, each its own LibraryIndex)
// answers, merged, as the one library holding every part: the exact search bit for bit.
#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/index/library_index.h"
#include "core/search/exact_search.h"
#include "core/search/merge_part_results.h"
#include "tests/search_test_data.h"

namespace motiondb {
namespace {

constexpr int kDims = 12;

// Nine clips of noise with the pattern planted at 1x, 1.4x and 0.75x in some, and an exact copy
// of the first under another id (its matches tie the first's score for score). Ids are neither
// in the order of the list nor of any part, so only a tie broken by id ranks alike everywhere.
std::vector<LibraryClip> Clips() {
  const std::vector<int64_t> ids = {907, 15, 433, 8, 1200, 61, 77, 390, 5};
  std::vector<LibraryClip> clips;
  for (size_t c = 0; c < ids.size(); ++c) {
    RowMatrixXf curve = testing::SmoothNoise(900, kDims, 40 + static_cast<uint32_t>(c));
    if (c % 3 != 2) testing::Plant(curve, testing::Pattern(40 + 8 * (c % 4), kDims), 120 + 50 * c);
    if (c % 2 == 0) testing::Plant(curve, testing::Pattern(56 - 6 * (c % 3), kDims), 600);
    clips.push_back({ids[c], "clip" + std::to_string(ids[c]), {}, std::move(curve)});
  }
  LibraryClip copy = clips.front();
  copy.clip_id = 640;
  copy.name = "copy of clip907";
  clips.push_back(std::move(copy));
  return clips;
}

// The clips split by id into `count` parts, each part's clips in reverse order.
std::vector<std::vector<LibraryClip>> Parts(const std::vector<LibraryClip>& clips, int count) {
  std::vector<std::vector<LibraryClip>> parts(count);
  for (auto clip = clips.rbegin(); clip != clips.rend(); ++clip) {
    parts[clip->clip_id % count].push_back(*clip);
  }
  return parts;
}

void ExpectSameResults(const std::vector<SearchResult>& merged,
                       const std::vector<SearchResult>& whole) {
  ASSERT_EQ(merged.size(), whole.size());
  for (size_t i = 0; i < whole.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "result " << i);
    EXPECT_EQ(merged[i].clip_id, whole[i].clip_id);
    EXPECT_EQ(merged[i].clip_name, whole[i].clip_name);
    EXPECT_EQ(merged[i].first_frame, whole[i].first_frame);
    EXPECT_EQ(merged[i].last_frame, whole[i].last_frame);
    EXPECT_EQ(merged[i].score, whole[i].score);  // bit for bit
    EXPECT_EQ(merged[i].start_s, whole[i].start_s);
    EXPECT_EQ(merged[i].end_s, whole[i].end_s);
    EXPECT_EQ(merged[i].path, whole[i].path);
  }
}

TEST(SearchPartsTest, ExactSearchOverPartsMergesToTheWholeLibrarysAnswer) {
  const std::vector<LibraryClip> clips = Clips();
  const std::unique_ptr<LibraryIndex> whole = *LibraryIndex::Build(clips, 30.0, {});
  const std::vector<RowMatrixXf> queries = {testing::Pattern(40, kDims),
                                            testing::Pattern(60, kDims),
                                            clips[4].coordinates.middleRows(200, 45)};
  for (const int part_count : {2, 3, 4}) {
    std::vector<std::unique_ptr<LibraryIndex>> parts;
    for (std::vector<LibraryClip>& part : Parts(clips, part_count)) {
      if (!part.empty()) parts.push_back(*LibraryIndex::Build(std::move(part), 30.0, {}));
    }
    for (size_t q = 0; q < queries.size(); ++q) {
      for (const int max_results : {3, 10, 40}) {
        SCOPED_TRACE(::testing::Message()
                     << part_count << " parts, query " << q << ", max_results " << max_results);
        SearchParams params;
        params.max_results = max_results;
        params.return_path = true;
        const CoordinateView query = CoordinateView::Of(queries[q]);
        const absl::StatusOr<SearchResponse> expected = ExactSearch(*whole, query, params);
        ASSERT_TRUE(expected.ok()) << expected.status();
        std::vector<std::vector<SearchResult>> answers;
        for (const std::unique_ptr<LibraryIndex>& part : parts) {
          absl::StatusOr<SearchResponse> answer = ExactSearch(*part, query, params);
          ASSERT_TRUE(answer.ok()) << answer.status();
          answers.push_back(std::move(answer->results));
        }
        ExpectSameResults(MergePartResults(std::move(answers), max_results), expected->results);
      }
    }
  }
}

// The copy's matches tie the original's: the lower id first, in the whole library (where the
// copy comes last) as in the parts.
TEST(SearchPartsTest, AnExactCopyRanksByIdWhereverItLies) {
  const std::vector<LibraryClip> clips = Clips();
  const std::unique_ptr<LibraryIndex> whole = *LibraryIndex::Build(clips, 30.0, {});
  SearchParams params;
  params.max_results = 4;
  const RowMatrixXf query = clips[0].coordinates.middleRows(300, 40);
  const SearchResponse found = *ExactSearch(*whole, CoordinateView::Of(query), params);
  ASSERT_GE(found.results.size(), 2u);
  EXPECT_EQ(found.results[0].score, 0.0);
  EXPECT_EQ(found.results[1].score, 0.0);
  EXPECT_EQ(found.results[0].clip_id, 640);  // the copy: added last, the lower id
  EXPECT_EQ(found.results[1].clip_id, 907);
}

SearchResult Result(int64_t clip_id, double score, int64_t first) {
  SearchResult result;
  result.clip_id = clip_id;
  result.score = score;
  result.first_frame = first;
  result.last_frame = first + 10;
  return result;
}

TEST(SearchPartsTest, MergeKeepsTheBestAcrossPartsAndBreaksTiesById) {
  std::vector<std::vector<SearchResult>> parts = {
      {Result(9, 0.5, 0), Result(9, 0.7, 100)},
      {},
      {Result(4, 0.5, 50), Result(4, 0.6, 0), Result(4, 0.9, 300)},
  };
  const std::vector<SearchResult> merged = MergePartResults(parts, 4);
  ASSERT_EQ(merged.size(), 4u);
  const std::vector<std::pair<int64_t, double>> expected = {{4, 0.5}, {9, 0.5}, {4, 0.6}, {9, 0.7}};
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(merged[i].clip_id, expected[i].first);
    EXPECT_EQ(merged[i].score, expected[i].second);
  }
  EXPECT_EQ(MergePartResults(parts, 10).size(), 5u);
  EXPECT_TRUE(MergePartResults(parts, 0).empty());
  EXPECT_TRUE(MergePartResults({}, 5).empty());
}

}  // namespace
}  // namespace motiondb
