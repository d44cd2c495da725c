// Propagation (server/jobs/propagation.h): which candidate ranges are kept, and the space's score
// scale behind the similarity factor, on a real library and space.
#include "server/jobs/propagation.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "server/catalog.h"
#include "testing/synthetic_corpus.h"
#include "tests/test_data.h"

namespace motiondb::server {
namespace {

using testing::GenerateSyntheticCorpus;
using testing::SyntheticAction;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;
using testing::SyntheticSegment;

storage::LabelRecord Range(int64_t first, int64_t last, double value, double score = 0.1) {
  storage::LabelRecord label;
  label.clip_id = 1;
  label.first_frame = first;
  label.last_frame = last;
  label.descriptor = "raise";
  label.value = value;
  label.score = score;
  label.origin = storage::LabelOrigin::kPropagated;
  return label;
}

// Overlap is measured against the shorter range: a long weaker range holding a stronger short
// one is dropped (against the long one's own length it shares only a fifth).
// The job's parameters name its seed selection, each by its own name.
TEST(ParametersJson, NamesTheSeedSelection) {
  PropagationRequest request;
  request.space = "body";
  for (const auto& [selection, name] :
       {std::pair{SeedSelection::kNearestFrames, "\"nearest_frames\""},
        std::pair{SeedSelection::kDistinctPlaces, "\"distinct_places\""},
        std::pair{SeedSelection::kNearestWindows, "\"nearest_windows\""}}) {
    request.search.params.seed_selection = selection;
    const std::string json = ParametersJson(request);
    EXPECT_NE(json.find(absl::StrCat("\"seed_selection\":", name)), std::string::npos) << json;
  }
}

TEST(KeepStrongest, DropsALongWeakerRangeAroundAStrongerShortOne) {
  const std::vector<storage::LabelRecord> kept =
      KeepStrongest({Range(0, 99, 0.5), Range(40, 59, 0.9)}, {});
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].first_frame, 40);
  EXPECT_EQ(kept[0].last_frame, 59);
}

TEST(KeepStrongest, ALongCandidateDoesNotWriteOverAManualRange) {
  storage::LabelRecord manual = Range(40, 59, 1.0);
  manual.origin = storage::LabelOrigin::kManual;
  EXPECT_TRUE(KeepStrongest({Range(0, 99, 0.5)}, {manual}).empty());
}

TEST(KeepStrongest, KeepsRangesSharingHalfOrLessOfTheShorterOne) {
  // 10 shared frames of a 20-frame range: exactly half, kept.
  const std::vector<storage::LabelRecord> kept =
      KeepStrongest({Range(0, 99, 0.5), Range(90, 109, 0.9)}, {});
  EXPECT_EQ(kept.size(), 2u);
}

storage::LabelRecord Rival(int64_t first, int64_t last, double value) {
  storage::LabelRecord label = Range(first, last, value);
  label.descriptor = "shrug";
  return label;
}

// Two descriptors nearly as strong on one range: neither is written; a clearly stronger one is.
TEST(DropContested, KeepsARangeOnlyWhereNoOtherDescriptorComesNearIt) {
  EXPECT_TRUE(DropContested({Range(0, 99, 1.0), Rival(10, 109, 0.95)}, 0.9).empty());
  const std::vector<storage::LabelRecord> kept =
      DropContested({Range(0, 99, 1.0), Rival(10, 109, 0.5)}, 0.9);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].descriptor, "raise");
  // Share 1: of two equal values neither is written, the stronger of two different ones is.
  EXPECT_TRUE(DropContested({Range(0, 99, 0.5), Rival(0, 99, 0.5)}, 1).empty());
  EXPECT_EQ(DropContested({Range(0, 99, 0.6), Rival(0, 99, 0.5)}, 1).size(), 1u);
}

// Rivals are ranges of another descriptor on the same clip sharing more than half of the
// shorter one; ranges of one descriptor are never rivals (KeepStrongest settled those).
TEST(DropContested, OnlyOverlappingRangesOfAnotherDescriptorOnItsClipAreRivals) {
  storage::LabelRecord elsewhere = Rival(0, 99, 1.0);
  elsewhere.clip_id = 2;
  const std::vector<storage::LabelRecord> candidates = {Range(0, 99, 0.5), Range(50, 149, 0.5),
                                                        Rival(140, 159, 1.0), elsewhere};
  const std::vector<storage::LabelRecord> kept = DropContested(candidates, 0.9);
  ASSERT_EQ(kept.size(), 4u);  // the rival shares exactly half of its 20 frames with the second
  for (size_t i = 0; i < kept.size(); ++i)
    EXPECT_EQ(kept[i].first_frame, candidates[i].first_frame);
  EXPECT_EQ(DropContested({Range(0, 99, 0.5), Rival(85, 104, 1.0)}, 0.9).size(), 1u);
}

// 20 minutes of synthetic capture at 30 Hz in clips of a minute (tagged "even" and "odd" by
// turns), a space over them, and manual labels "raise" and "shrug" on its first actions.
class SpaceScaleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("propagation_test");
    auto opened = storage::Database::Open((dir_ / "library.sqlite").string());
    ASSERT_TRUE(opened.ok()) << opened.status();
    database_ = std::move(*opened);
    catalog_ = std::make_unique<Catalog>(*database_, registry_);
    SyntheticCorpusOptions options;
    options.fps = 30;
    options.target_duration_s = 1200;
    options.max_clip_duration_s = 60;
    const absl::StatusOr<SyntheticCorpus> corpus = GenerateSyntheticCorpus(options);
    ASSERT_TRUE(corpus.ok()) << corpus.status();
    std::vector<int64_t> ids;
    for (size_t c = 0; c < corpus->clips.size(); ++c) {
      storage::ClipRecord record;
      record.name = absl::StrCat("clip_", c);
      record.source_file = record.name + ".bvh";
      record.tags = {c % 2 == 0 ? "even" : "odd"};
      const absl::StatusOr<IngestedClip> ingested = catalog_->IngestClip(record, corpus->clips[c]);
      ASSERT_TRUE(ingested.ok()) << ingested.status();
      ids.push_back(ingested->record.clip_id);
    }
    SpaceRequest space;
    space.name = "body";
    space.training = {{ids.front(), std::nullopt, std::nullopt}};
    ASSERT_TRUE(catalog_->CreateSpace(space, [] { return false; }).ok());
    std::vector<storage::LabelRecord> labels;
    for (const SyntheticSegment& segment : corpus->segments) {
      const bool raise = segment.action == SyntheticAction::kRightArmRaise;
      if (!raise && segment.action != SyntheticAction::kShrug) continue;
      storage::LabelRecord& label = labels.emplace_back();
      label.clip_id = ids[segment.clip];
      label.first_frame = segment.first_frame;
      label.last_frame = segment.last_frame;
      label.descriptor = raise ? "raise" : "shrug";
      label.value = raise ? 1.0 : 0.8;
      label.origin = storage::LabelOrigin::kManual;
      if (labels.size() == 6) break;
    }
    ASSERT_TRUE(database_->AddLabels(labels).ok());
    runner_ = std::make_unique<SearchRunner>(registry_, *database_, UploadLimits{});
  }

  void TearDown() override { std::filesystem::remove_all(dir_); }

  // The job's output; `scales` fresh for each job, so that none reuses another's s0.
  storage::PropagationOutput Propagate(const std::vector<std::string>& descriptors,
                                       const std::vector<std::string>& tags, int max_results,
                                       int threads = 1) {
    PropagationRequest request;
    request.space = "body";
    request.descriptors = descriptors;
    request.search.params.tags = tags;
    request.search.params.max_results = max_results;
    ScoreScales scales;
    absl::StatusOr<storage::PropagationOutput> output = RunPropagation(
        *database_, registry_, *runner_, scales, request, "job-1", threads, [] { return false; },
        [](const PropagationProgress&) {});
    EXPECT_TRUE(output.ok()) << output.status();
    return output.ok() ? *output : storage::PropagationOutput();
  }

  std::filesystem::path dir_;
  std::unique_ptr<storage::Database> database_;
  IndexRegistry registry_;
  std::unique_ptr<Catalog> catalog_;
  std::unique_ptr<SearchRunner> runner_;
};

// Each propagated label's value v of a manual value m and score s gives back the s0 its job
// used: s / sqrt(-log2(v / m)). The jobs differ in descriptors, tags and max_results; with s0
// taken from a job's own searches they would give different ones.
TEST_F(SpaceScaleTest, TheScaleDoesNotDependOnTheJob) {
  const absl::StatusOr<double> scale =
      SpaceScoreScale(*registry_.Find("body"), *runner_, /*threads=*/1, [] { return false; });
  ASSERT_TRUE(scale.ok()) << scale.status();
  ASSERT_NE(*scale, 1.0) << "no window of the sample got a full list: the library is too small";
  const absl::StatusOr<storage::LabelPage> manual =
      database_->ListLabels({.page_size = 100, .page_token = ""}, {});
  ASSERT_TRUE(manual.ok()) << manual.status();
  std::map<int64_t, double> manual_values;
  for (const storage::LabelRecord& label : manual->labels) {
    manual_values[label.label_id] = label.value;
  }
  int checked = 0;
  for (const auto& output : {Propagate({"raise"}, {}, 100), Propagate({"shrug"}, {"odd"}, 10),
                             Propagate({"raise", "shrug"}, {"even"}, 40)}) {
    for (const storage::LabelRecord& label : output.labels) {
      const double ratio = label.value / manual_values.at(label.source_label_id);
      if (!(ratio > 1e-6 && ratio < 1 - 1e-6) || label.score <= 0) continue;
      EXPECT_NEAR(label.score / std::sqrt(-std::log2(ratio)), *scale, 1e-6 * *scale);
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

// The cache answers from the scale measured for the snapshot the registry holds.
TEST_F(SpaceScaleTest, TheCacheKeepsTheScaleOfASnapshot) {
  ScoreScales scales;
  const auto snapshot = registry_.Find("body");
  const absl::StatusOr<double> first = scales.Get(snapshot, *runner_, 1, [] { return false; });
  ASSERT_TRUE(first.ok()) << first.status();
  // Measured again, a stop request cancels it; answered from the cache, it is not asked.
  const absl::StatusOr<double> cached = scales.Get(snapshot, *runner_, 1, [] { return true; });
  ASSERT_TRUE(cached.ok()) << cached.status();
  EXPECT_EQ(*cached, *first);
  EXPECT_TRUE(
      absl::IsCancelled(ScoreScales().Get(snapshot, *runner_, 1, [] { return true; }).status()));
}

// A job's searches spread over threads give the output one thread gives, label for label, and
// the space's scale is measured the same on any number of threads.
TEST_F(SpaceScaleTest, TheOutputDoesNotDependOnTheThreads) {
  const storage::PropagationOutput one = Propagate({"raise", "shrug"}, {}, 40, 1);
  ASSERT_FALSE(one.labels.empty());
  for (int threads : {2, 5}) {
    const storage::PropagationOutput many = Propagate({"raise", "shrug"}, {}, 40, threads);
    ASSERT_EQ(many.labels.size(), one.labels.size()) << threads << " threads";
    for (size_t i = 0; i < one.labels.size(); ++i) {
      const storage::LabelRecord& a = one.labels[i];
      const storage::LabelRecord& b = many.labels[i];
      EXPECT_EQ(std::tie(a.clip_id, a.first_frame, a.last_frame, a.descriptor, a.source_label_id),
                std::tie(b.clip_id, b.first_frame, b.last_frame, b.descriptor, b.source_label_id))
          << "label " << i << ", " << threads << " threads";
      EXPECT_EQ(a.value, b.value) << "label " << i << ", " << threads << " threads";
      EXPECT_EQ(a.score, b.score) << "label " << i << ", " << threads << " threads";
    }
    EXPECT_EQ(many.job.queries, one.job.queries);
    EXPECT_EQ(many.job.done, one.job.done);
  }
  const auto snapshot = registry_.Find("body");
  const absl::StatusOr<double> scale_one =
      SpaceScoreScale(*snapshot, *runner_, 1, [] { return false; });
  const absl::StatusOr<double> scale_three =
      SpaceScoreScale(*snapshot, *runner_, 3, [] { return false; });
  ASSERT_TRUE(scale_one.ok() && scale_three.ok());
  EXPECT_EQ(*scale_one, *scale_three);
}

}  // namespace
}  // namespace motiondb::server
