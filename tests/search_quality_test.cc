// Retrieval quality (issue 4): the thesis's synthetic validation (6.3.2), and precision and
// recall on real labelled capture (../shared/mocap/bandai2-normal, skipped when absent).
#include <algorithm>
#include <map>

#include <gtest/gtest.h>

#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "core/space/search_coordinates.h"
#include "testing/labelled_index.h"
#include "testing/learned_metric_folds.h"
#include "testing/retrieval_evaluation.h"
#include "testing/synthetic_corpus.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using testing::EvaluateRetrieval;
using testing::GenerateSyntheticCorpus;
using testing::RetrievalOptions;
using testing::RetrievalReport;
using testing::SyntheticAction;
using testing::SyntheticActionName;
using testing::SyntheticCorpus;
using testing::SyntheticSegment;

class SyntheticValidation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    absl::StatusOr<SyntheticCorpus> generated = GenerateSyntheticCorpus({});
    ASSERT_TRUE(generated.ok()) << generated.status();
    synthetic_ = new SyntheticCorpus(*std::move(generated));
    std::vector<TrainingClip> training;
    for (const Clip& clip : synthetic_->clips)
      training.push_back({"synthetic", clip, std::nullopt});
    absl::StatusOr<MotionSpace> space = MotionSpace::Build(training, {});
    ASSERT_TRUE(space.ok()) << space.status();
    space_ = new MotionSpace(*std::move(space));
    std::vector<LibraryClip> clips;
    for (size_t c = 0; c < synthetic_->clips.size(); ++c) {
      clips.push_back({static_cast<int64_t>(c),
                       "synthetic",
                       {},
                       *SearchCoordinates(*space_, synthetic_->clips[c])});
    }
    library_ = LibraryIndex::Build(std::move(clips), space_->sample_rate(), {})->release();
  }
  static void TearDownTestSuite() {
    delete library_;
    delete space_;
    delete synthetic_;
  }

  // A ground-truth segment's frames at the space rate.
  static std::pair<int64_t, int64_t> AtSpaceRate(const SyntheticSegment& s) {
    const double ratio = space_->sample_rate() * synthetic_->clips[s.clip].frame_time();
    return {std::llround(s.first_frame * ratio), std::llround(s.last_frame * ratio)};
  }

  // The segment a result covers (more than half of the segment), or -1.
  static int MatchedSegment(const SearchResult& r) {
    for (size_t g = 0; g < synthetic_->segments.size(); ++g) {
      const SyntheticSegment& s = synthetic_->segments[g];
      if (s.clip != r.clip_index) continue;
      const auto [first, last] = AtSpaceRate(s);
      const int64_t overlap = std::min(r.last_frame, last) - std::max(r.first_frame, first) + 1;
      if (overlap > 0.5 * (last - first + 1)) return static_cast<int>(g);
    }
    return -1;
  }

  // The segment's frames as a query at the space rate, with `params.characteristic_frame` set to
  // its peak (the first frame of the peak hold), as the thesis chose it by hand.
  static RowMatrixXf QueryAtPeak(const SyntheticSegment& segment, SearchParams& params) {
    const Clip& clip = synthetic_->clips[segment.clip];
    RowMatrixXf query =
        *SearchCoordinates(*space_, *clip.Slice({segment.first_frame, segment.last_frame}));
    params.characteristic_frame = static_cast<int>(std::min<int64_t>(
        query.rows() - 1, std::llround((segment.peak_first_frame - segment.first_frame) *
                                       space_->sample_rate() * clip.frame_time())));
    return query;
  }

  static SyntheticCorpus* synthetic_;
  static MotionSpace* space_;
  static LibraryIndex* library_;
};

SyntheticCorpus* SyntheticValidation::synthetic_ = nullptr;
MotionSpace* SyntheticValidation::space_ = nullptr;
LibraryIndex* SyntheticValidation::library_ = nullptr;

// Querying with the first instance of each class ranks every instance of that class above every
// instance of another class. As in the thesis, the characteristic point is the moment of
// maximum extension (the first frame of the peak hold).
TEST_F(SyntheticValidation, FirstInstanceRanksItsWholeClassFirst) {
  for (SyntheticAction action :
       {SyntheticAction::kRightArmRaise, SyntheticAction::kLeftArmRaise,
        SyntheticAction::kBothArmsRaise, SyntheticAction::kShrug, SyntheticAction::kSlouch}) {
    SCOPED_TRACE(SyntheticActionName(action));
    const auto first = std::find_if(synthetic_->segments.begin(), synthetic_->segments.end(),
                                    [&](const SyntheticSegment& s) { return s.action == action; });
    ASSERT_NE(first, synthetic_->segments.end());
    SearchParams params;
    params.max_results = 200;
    params.neighbours = 2000;
    const RowMatrixXf query = QueryAtPeak(*first, params);
    absl::StatusOr<SearchResponse> response = Search(*library_, CoordinateView::Of(query), params);
    ASSERT_TRUE(response.ok()) << response.status();

    const int instances = static_cast<int>(
        std::count_if(synthetic_->segments.begin(), synthetic_->segments.end(),
                      [&](const SyntheticSegment& s) { return s.action == action; }));
    std::vector<bool> found(synthetic_->segments.size(), false);
    int same_found = 0, last_same_rank = -1, first_other_rank = -1;
    for (size_t rank = 0; rank < response->results.size(); ++rank) {
      const int g = MatchedSegment(response->results[rank]);
      if (g < 0 || found[g]) continue;
      found[g] = true;
      if (synthetic_->segments[g].action == action) {
        ++same_found;
        last_same_rank = static_cast<int>(rank);
      } else if (first_other_rank < 0) {
        first_other_rank = static_cast<int>(rank);
      }
    }
    EXPECT_EQ(same_found, instances);
    if (first_other_rank >= 0) {
      EXPECT_LT(last_same_rank, first_other_rank);
    }
  }
}

// The fast search's recall@10 against the exact search, over the first instance of each class
// as the query (characteristic point at its peak): at least 0.9. Measured 50 of 50 with
// refinement; 37 of 50 without it, because a warp forced through its seed scores a little worse
// than the free optimum, which reorders the 15-20 nearly equal instances of a class.
TEST_F(SyntheticValidation, FastRecallAgainstExactAtTen) {
  int found = 0, total = 0;
  for (SyntheticAction action :
       {SyntheticAction::kRightArmRaise, SyntheticAction::kLeftArmRaise,
        SyntheticAction::kBothArmsRaise, SyntheticAction::kShrug, SyntheticAction::kSlouch}) {
    const auto first = std::find_if(synthetic_->segments.begin(), synthetic_->segments.end(),
                                    [&](const SyntheticSegment& s) { return s.action == action; });
    SearchParams params;
    params.max_results = 10;
    const RowMatrixXf query = QueryAtPeak(*first, params);
    const SearchResponse exact = *ExactSearch(*library_, CoordinateView::Of(query), params);
    const SearchResponse fast = *Search(*library_, CoordinateView::Of(query), params);
    for (const SearchResult& e : exact.results) {
      ++total;
      found += std::any_of(fast.results.begin(), fast.results.end(), [&](const SearchResult& f) {
        return Overlaps(e, f, 0.5) || Overlaps(f, e, 0.5);
      });
    }
  }
  ASSERT_EQ(total, 50);
  EXPECT_GE(found, 45) << found << " of " << total;
}

// The held-out split's halves (testing::Takes): of each content's takes in name order, the first
// ceil(n/2) and the others, together every take once.
TEST(BandaiQuality, TakeHalvesPartitionEachContent) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  std::vector<std::string> all_labels, first_labels, second_labels;
  const auto all = testing::ReadLabelledFolder(mocap / "bandai2-normal", &all_labels);
  const auto first = testing::ReadLabelledFolder(mocap / "bandai2-normal", &first_labels,
                                                 testing::Takes::kFirstHalf);
  const auto second = testing::ReadLabelledFolder(mocap / "bandai2-normal", &second_labels,
                                                  testing::Takes::kSecondHalf);
  ASSERT_TRUE(all.ok() && first.ok() && second.ok());
  ASSERT_EQ(first->size() + second->size(), all->size());
  std::map<std::string, int> count, first_count;
  for (const std::string& label : all_labels) ++count[label];
  for (const std::string& label : first_labels) ++first_count[label];
  for (const auto& [label, n] : count) EXPECT_EQ(first_count[label], (n + 1) / 2) << label;
  std::vector<std::string> names;
  for (const auto* half : {&*first, &*second}) {
    for (const TrainingClip& clip : *half) names.push_back(clip.source);
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(std::adjacent_find(names.begin(), names.end()), names.end());
  // Within a content, every first-half take sorts before every second-half one.
  std::map<std::string, std::string> last_first;
  for (size_t i = 0; i < first->size(); ++i) last_first[first_labels[i]] = (*first)[i].source;
  for (size_t i = 0; i < second->size(); ++i) {
    EXPECT_LT(last_first[second_labels[i]], (*second)[i].source);
  }
}

// Each clip as a query against all the others: precision@5 of the content class >= 0.98 (0.988
// measured) and the fast search's recall@10 against exact search >= 0.95 (0.977 measured), with
// the default (unit) metric.
TEST(BandaiQuality, LeaveOneOutPrecisionAndRecall) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  absl::StatusOr<testing::LabelledIndex> library =
      testing::LoadLabelledIndex({mocap / "bandai2-normal"}, {}, {});
  ASSERT_TRUE(library.ok()) << library.status();
  ASSERT_EQ(library->index->clip_count(), 465);
  RetrievalOptions options;
  options.exact_every = 10;
  absl::StatusOr<RetrievalReport> report =
      EvaluateRetrieval(*library->index, library->labels, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_GE(report->precision, 0.98);
  EXPECT_GE(report->exact_precision, 0.8);
  EXPECT_GE(report->recall, 0.95);
  for (const auto& [label, precision] : report->precision_by_label) {
    EXPECT_GE(precision, 0.6) << label;
  }
}

// Each style of bandai1 as queries against the other 14 styles (17 contents; contents with fewer
// than 5 clips elsewhere left out): precision@5 >= 0.6 (0.648 measured with the root velocity,
// 0.360 without it); walk-left and walk-right, walks turned in the capture room, are found as
// walks more than as themselves. Then in a metric learned from the labels, each style's queries
// in one fitted on the other 14 styles only, the search's defaults otherwise: precision@5 >= 0.78
// (0.806 measured), walk-left found as itself (0.947 measured, 0.387 in the space's metric).
TEST(BandaiQuality, LeaveStyleOutPrecision) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  absl::StatusOr<testing::LabelledIndex> library =
      testing::LoadLabelledIndex({mocap / "bandai1"}, {}, {});
  ASSERT_TRUE(library.ok()) << library.status();
  RetrievalOptions options;
  options.exact_every = 0;
  options.groups = library->styles;
  absl::StatusOr<RetrievalReport> report =
      EvaluateRetrieval(*library->index, library->labels, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->queries, 165);
  EXPECT_EQ(report->skipped_queries, 9);
  EXPECT_EQ(report->precision_by_group.size(), 15u);
  EXPECT_GE(report->precision, 0.6);
  EXPECT_GE(report->precision_by_label.at("walk-back"), 0.9);  // 0.973: the root velocity's

  report = testing::EvaluateInLearnedMetric(*library, options, {});
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->queries, 165);
  EXPECT_EQ(report->precision_by_group.size(), 15u);
  EXPECT_GE(report->precision, 0.78);
  EXPECT_GE(report->precision_by_label.at("walk-left"), 0.85);
}

// bandai2-normal's clips as queries against bandai1 (one space on both), on the contents they
// share (walk, run): precision@5 >= 0.5 (0.571 measured, 0.397 without the root velocity). Then
// within one style in a metric learned from the other dataset (fitted on bandai1's styles,
// bandai2-normal's clips searched among themselves): precision@5 stays >= 0.98 (0.992 measured).
TEST(BandaiQuality, CrossDatasetPrecision) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  absl::StatusOr<testing::LabelledIndex> library =
      testing::LoadLabelledIndex({mocap / "bandai2-normal", mocap / "bandai1"}, {}, {});
  ASSERT_TRUE(library.ok()) << library.status();
  RetrievalOptions options;
  options.exact_every = 0;
  options.groups = library->sources;
  for (const std::string& source : library->sources) {
    options.queries.push_back(source == "bandai2-normal");
  }
  absl::StatusOr<RetrievalReport> report =
      EvaluateRetrieval(*library->index, library->labels, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->queries, 76);
  EXPECT_EQ(report->precision_by_label.size(), 2u);
  EXPECT_GE(report->precision, 0.5);

  RetrievalOptions within;
  within.exact_every = 0;
  report = testing::EvaluateFirstSourceInLearnedMetric(*library, within, {});
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->queries, 465);
  EXPECT_GE(report->precision, 0.98);
}

}  // namespace
}  // namespace motiondb
