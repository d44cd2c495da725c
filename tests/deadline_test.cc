// Deadlines inside every long loop of a request (issue 37): a stop function that says stop from
// its n-th poll on ends each long operation with CANCELLED at that poll, without finishing the
// work (it makes no further poll, and polls far fewer times than the whole operation), and
// stores nothing; the query length limit refuses before anything is searched. Deterministic:
// the stop functions count their polls, nothing is timed. A search held inside its poll also
// shows the runner's choice of threads beside it.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_writer.h"
#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "core/search/warp/band_warp.h"
#include "core/search/warp/time_warp.h"
#include "server/catalog.h"
#include "server/edit/blends.h"
#include "server/edit/curves.h"
#include "server/edit/pose_models.h"
#include "server/edit/reconstruct.h"
#include "server/edit/transitions.h"
#include "server/search_runner.h"
#include "server/space_curve.h"
#include "server/upload/upload.h"
#include "testing/synthetic_corpus.h"
#include "tests/search_test_data.h"
#include "tests/test_data.h"
#include "util/parallel_for.h"
#include "util/stop_poll.h"

namespace motiondb {
namespace {

using testing::GenerateSyntheticCorpus;
using ::testing::HasSubstr;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

constexpr int64_t kNever = std::numeric_limits<int64_t>::max();

// A stop function that says stop from its (n + 1)-th poll on, counting its polls; safe to poll
// from several threads.
class StopAfter {
 public:
  explicit StopAfter(int64_t n) : n_(n) {}
  std::function<bool()> function() {
    return [this] { return polls_.fetch_add(1) >= n_; };
  }
  int64_t polls() const { return polls_; }

 private:
  const int64_t n_;
  std::atomic<int64_t> polls_{0};
};

// Polls every loop that runs on the threads of one operation may make after the one that said
// stop: one a thread.
int64_t LatePolls() { return ThreadsFor(0); }

TEST(StopPoll, AsksFirstThenOncePerPeriod) {
  StopAfter counter(kNever);
  const std::function<bool()> should_stop = counter.function();
  StopPoll poll(should_stop, 10);
  EXPECT_FALSE(poll.Done(1));
  EXPECT_EQ(counter.polls(), 1);
  for (int i = 0; i < 9; ++i) EXPECT_FALSE(poll.Done(1));
  EXPECT_EQ(counter.polls(), 1);
  EXPECT_FALSE(poll.Done(1));
  EXPECT_EQ(counter.polls(), 2);
  EXPECT_FALSE(poll.Done(25));
  EXPECT_EQ(counter.polls(), 3);

  StopAfter stopper(1);
  const std::function<bool()> stop_second = stopper.function();
  StopPoll stopping(stop_second, 10);
  EXPECT_FALSE(stopping.Done(10));
  EXPECT_TRUE(stopping.Done(10));
  EXPECT_TRUE(stopping.Done(1));  // stays stopped, asking no more
  EXPECT_EQ(stopper.polls(), 2);
  EXPECT_FALSE(StopPoll().Done(kNever));
}

// `warp` (a warp of millions of cells, told to `stop`) runs to its end without a stop, and
// stops at the poll that says stop, inside the warp.
void ExpectStopsInsideOneWarp(const std::function<std::optional<Warp>(StopPoll*)>& warp) {
  const auto run = [&](StopAfter& counter) {
    const std::function<bool()> should_stop = counter.function();
    StopPoll stop(should_stop, int64_t{1} << 20);
    const bool found = warp(&stop).has_value();
    return std::make_pair(found, stop.stopped());
  };
  StopAfter whole(kNever);
  EXPECT_EQ(run(whole), std::make_pair(true, false));
  ASSERT_GE(whole.polls(), 3);
  StopAfter stopped(1);
  EXPECT_EQ(run(stopped), std::make_pair(false, true));
  EXPECT_EQ(stopped.polls(), 2);
}

TEST(WarpStops, InsideOneAnchoredWarp) {
  const RowMatrixXf query = testing::SmoothNoise(2000, 5, 1);
  const RowMatrixXf clip = testing::SmoothNoise(6000, 5, 2);
  ExpectStopsInsideOneWarp([&](StopPoll* stop) {
    WarpWorkspace workspace;
    return AnchoredWarp(CoordinateView::Of(query), CoordinateView::Of(clip), 1000, 3000, {},
                        /*with_path=*/true, workspace, std::numeric_limits<float>::infinity(),
                        stop);
  });
}

TEST(WarpStops, InsideOneBandWarp) {
  const RowMatrixXf query = testing::SmoothNoise(40000, 5, 3);
  const RowMatrixXf clip = testing::SmoothNoise(40000, 5, 4);
  std::vector<int64_t> centre(40000);
  for (int64_t i = 0; i < 40000; ++i) centre[i] = i;
  ExpectStopsInsideOneWarp([&](StopPoll* stop) {
    BandWorkspace workspace;
    bool touches_edge = false;
    return BandWarp(CoordinateView::Of(query), CoordinateView::Of(clip), centre, 20, {}, workspace,
                    &touches_edge, std::numeric_limits<float>::infinity(), stop);
  });
}

// 6 minutes of synthetic capture at 30 Hz in two clips, stored with a space "body" over them,
// as the server holds a library.
class DeadlineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::filesystem::path(testing::MakeTempDir("deadline_test"));
    auto opened = storage::Database::Open((*dir_ / "library.sqlite").string());
    ASSERT_TRUE(opened.ok()) << opened.status();
    database_ = opened->release();
    registry_ = new server::IndexRegistry();
    catalog_ = new server::Catalog(*database_, *registry_);
    SyntheticCorpusOptions options;
    options.fps = 30;
    options.target_duration_s = 360;
    options.max_clip_duration_s = 180;
    const absl::StatusOr<SyntheticCorpus> corpus = GenerateSyntheticCorpus(options);
    ASSERT_TRUE(corpus.ok()) << corpus.status();
    clip_ids_ = new std::vector<int64_t>();
    for (size_t c = 0; c < corpus->clips.size(); ++c) {
      storage::ClipRecord record;
      record.name = absl::StrCat("clip_", c);
      record.source_file = record.name + ".bvh";
      const absl::StatusOr<server::IngestedClip> ingested =
          catalog_->IngestClip(record, corpus->clips[c]);
      ASSERT_TRUE(ingested.ok()) << ingested.status();
      clip_ids_->push_back(ingested->record.clip_id);
    }
    bvh_ = new std::string(*WriteBvh(corpus->clips.front()));
    server::SpaceRequest space;
    space.name = "body";
    space.training = {{clip_ids_->front(), std::nullopt, std::nullopt}};
    ASSERT_TRUE(catalog_->CreateSpace(space, [] { return false; }).ok());
  }

  static void TearDownTestSuite() {
    delete catalog_;
    delete registry_;
    delete database_;
    std::filesystem::remove_all(*dir_);
    delete dir_;
    delete clip_ids_;
    delete bvh_;
  }

  static std::shared_ptr<const server::SpaceSnapshot> Snapshot() { return registry_->Find("body"); }
  static const LibraryIndex& Index() { return *Snapshot()->index; }
  // Rows [0, rows) of the first clip's search coordinates.
  static CoordinateView Query(int64_t rows) {
    return Index().clip_coordinates(0).middle_rows(0, rows);
  }
  static server::EditContext Edits() { return {*database_, *catalog_, *registry_}; }
  static int64_t StoredClips() {
    const absl::StatusOr<storage::ClipPage> page = database_->ListClips({});
    return page.ok() ? page->total_size : -1;
  }

  static std::filesystem::path* dir_;
  static storage::Database* database_;
  static server::IndexRegistry* registry_;
  static server::Catalog* catalog_;
  static std::vector<int64_t>* clip_ids_;
  static std::string* bvh_;  // the first clip's BVH
};

std::filesystem::path* DeadlineTest::dir_ = nullptr;
storage::Database* DeadlineTest::database_ = nullptr;
server::IndexRegistry* DeadlineTest::registry_ = nullptr;
server::Catalog* DeadlineTest::catalog_ = nullptr;
std::vector<int64_t>* DeadlineTest::clip_ids_ = nullptr;
std::string* DeadlineTest::bvh_ = nullptr;

// An operation run with a stop function; its status.
using Operation = std::function<absl::Status(const std::function<bool()>&)>;

// Runs `op` to its end, counting its polls (then `undo`, if any), then with a stop from its
// first poll, its second, its middle one and its last: each stopped run is CANCELLED at that
// poll (no more than a poll a thread after it).
void ExpectStopsAtEveryPoll(const Operation& op, int64_t min_polls,
                            const std::function<void()>& undo = {}) {
  StopAfter whole(kNever);
  const absl::Status finished = op(whole.function());
  EXPECT_TRUE(finished.ok()) << finished;
  if (undo) undo();
  EXPECT_GE(whole.polls(), min_polls) << "the operation polls too rarely to stop inside its work";
  for (const int64_t n : {int64_t{0}, int64_t{1}, whole.polls() / 2, whole.polls() - 1}) {
    StopAfter stop(n);
    const absl::Status stopped = op(stop.function());
    EXPECT_TRUE(absl::IsCancelled(stopped)) << "stopped at poll " << n << ": " << stopped;
    EXPECT_LE(stop.polls(), n + LatePolls()) << "stopped at poll " << n;
  }
}

TEST_F(DeadlineTest, FastSearchStopsInsideItsWarpsAndRefinement) {
  for (const bool refine : {true, false}) {
    SCOPED_TRACE(refine ? "refined" : "not refined");
    ExpectStopsAtEveryPoll(
        [&](const std::function<bool()>& should_stop) {
          SearchParams params;
          params.refine = refine;
          params.neighbours = 200;
          params.should_stop = should_stop;
          return Search(Index(), Query(refine ? 1500 : 600), params).status();
        },
        4);
  }
}

TEST_F(DeadlineTest, MultiPointSearchStops) {
  ExpectStopsAtEveryPoll(
      [&](const std::function<bool()>& should_stop) {
        SearchParams params;
        params.characteristic_points = 4;
        params.neighbours = 200;
        params.should_stop = should_stop;
        return Search(Index(), Query(900), params).status();
      },
      4);
}

// Every thread of the exact search stops within a poll of the stop.
TEST_F(DeadlineTest, ExactSearchStopsOnEveryThread) {
  for (const bool paths : {false, true}) {
    SCOPED_TRACE(paths ? "with paths" : "without paths");
    ExpectStopsAtEveryPoll(
        [&](const std::function<bool()>& should_stop) {
          SearchParams params;
          params.exact_threads = 2;
          params.return_path = paths;
          params.should_stop = should_stop;
          return ExactSearch(Index(), Query(600), params).status();
        },
        4);
  }
}

TEST_F(DeadlineTest, SearchRunnerStopsWhileParsingAnUploadedQuery) {
  const server::SearchRunner runner(*registry_, *database_, {}, 1'000'000);
  server::SearchRequest request;
  request.space = "body";
  request.query = server::UploadedQuery{*bvh_, 0, 300};
  request.threads = 1;  // one poll sequence: on several threads each member polls on its own
  ExpectStopsAtEveryPoll(
      [&](const std::function<bool()>& should_stop) {
        return runner.Run(request, should_stop).status();
      },
      4);
  // The text alone: a piece at a time.
  ASSERT_GT(bvh_->size(), size_t{1} << 20);
  StopAfter stop(1);
  EXPECT_TRUE(absl::IsCancelled(server::ReadUpload(*bvh_, "bvh", {}, stop.function()).status()));
  EXPECT_EQ(stop.polls(), 2);
}

// SearchRequest::threads unset: every core for a search alone, one beside another (here one held
// inside its first stop poll), so that a busy server gives each search a core as before.
TEST_F(DeadlineTest, SearchRunnerGivesEveryCoreOnlyToASearchAlone) {
  const server::SearchRunner runner(*registry_, *database_, {});
  server::SearchRequest request;
  request.space = "body";
  request.query = server::ClipSelection{clip_ids_->front(), 100, 160};
  const absl::StatusOr<server::SearchOutcome> alone = runner.Run(request, [] { return false; });
  ASSERT_TRUE(alone.ok()) << alone.status();
  EXPECT_EQ(alone->stats.threads, ThreadsFor(0));

  std::promise<void> entered, release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<bool> held_once = false;
  absl::StatusOr<server::SearchOutcome> held;
  std::thread holder([&] {
    held = runner.Run(request, [&] {
      if (!held_once.exchange(true)) {
        entered.set_value();
        released.wait();
      }
      return false;
    });
  });
  entered.get_future().wait();
  const absl::StatusOr<server::SearchOutcome> beside = runner.Run(request, [] { return false; });
  server::SearchRequest asked = request;
  asked.threads = 3;  // at most the cores
  const absl::StatusOr<server::SearchOutcome> three = runner.Run(asked, [] { return false; });
  release.set_value();
  holder.join();
  ASSERT_TRUE(beside.ok()) << beside.status();
  EXPECT_EQ(beside->stats.threads, 1);
  ASSERT_TRUE(three.ok()) << three.status();
  EXPECT_EQ(three->stats.threads, std::min(3, ThreadsFor(0)));
  ASSERT_TRUE(held.ok()) << held.status();
  EXPECT_EQ(held->stats.threads, ThreadsFor(0));
  // However many threads, the same hits.
  const server::SearchOutcome& held_outcome = *held;
  for (const server::SearchOutcome* outcome : {&*beside, &*three, &held_outcome}) {
    ASSERT_EQ(outcome->hits.size(), alone->hits.size());
    for (size_t i = 0; i < alone->hits.size(); ++i) {
      EXPECT_EQ(outcome->hits[i].clip_id, alone->hits[i].clip_id) << i;
      EXPECT_EQ(outcome->hits[i].start_frame, alone->hits[i].start_frame) << i;
      EXPECT_EQ(outcome->hits[i].score, alone->hits[i].score) << i;
    }
  }
}

TEST_F(DeadlineTest, RefusesAQueryOverTheLimitBeforeSearching) {
  const server::SearchRunner runner(*registry_, *database_, {}, 100);
  StopAfter counter(kNever);
  const auto run = [&](server::SearchRequest request) {
    request.space = "body";
    return runner.Run(request, counter.function()).status();
  };
  // Only the uploaded file's parsing polls before the length is known.
  server::SearchRequest stored;
  stored.query = server::ClipSelection{clip_ids_->front(), 0, 100};  // 101 frames at 30 Hz
  absl::Status status = run(stored);
  EXPECT_TRUE(absl::IsInvalidArgument(status)) << status;
  EXPECT_THAT(status.message(), HasSubstr("--max-query-frames"));
  EXPECT_THAT(status.message(), HasSubstr("101 frames"));
  server::SearchRequest uploaded;
  uploaded.query = server::UploadedQuery{*bvh_, 0, 10};  // the whole file is projected
  EXPECT_EQ(counter.polls(), 0);                         // refused before the search began
  status = run(uploaded);
  EXPECT_TRUE(absl::IsInvalidArgument(status)) << status;
  EXPECT_THAT(status.message(), HasSubstr("--max-query-frames"));
  EXPECT_THAT(status.message(), HasSubstr("bvh: "));
  const int64_t parsing_polls = counter.polls();
  // At slope limit 8, 100 frames warped at every frame fill 21 times the table of slope 2.
  server::SearchRequest steep;
  steep.query = server::ClipSelection{clip_ids_->front(), 0, 99};
  steep.params.slope_limit = 8;
  steep.params.refine = false;
  status = run(steep);
  EXPECT_TRUE(absl::IsInvalidArgument(status)) << status;
  EXPECT_THAT(status.message(), HasSubstr("slope_limit = 8"));
  EXPECT_THAT(status.message(), HasSubstr("--max-query-frames"));
  EXPECT_EQ(counter.polls(), parsing_polls);  // refused before the search began
  steep.params.slope_limit = 2;
  EXPECT_TRUE(run(steep).ok());
}

// Each operator with its result to store: stopped at any of its polls, it stores nothing.
TEST_F(DeadlineTest, EveryOperatorStopsAndStoresNothing) {
  const server::EditContext edits = Edits();
  // 2000 frames at 30 Hz: a few of every step's polls.
  const server::ClipSelection range{clip_ids_->front(), 0, 1999};
  const server::EditOutput output{"stopped_result", {}, "{}"};
  const auto curve_edit = [&] {
    server::CurveEdit edit;
    edit.space = "body";
    edit.clip = range;
    edit.output = output;
    return edit;
  };
  // The first clip's frames 0..first_last and the second's 0..second_last joined.
  const auto transition = [&](int first_last, int second_last, double gap_s,
                              double overlap_s) -> Operation {
    return [=, &edits](const std::function<bool()>& stop) {
      server::FillGapRequest request;
      request.space = "body";
      request.first = {clip_ids_->front(), 0, first_last};
      request.second = {(*clip_ids_)[1], 0, second_last};
      if (gap_s > 0) request.gap_s = gap_s;
      request.overlap_s = overlap_s;
      request.output = output;
      return server::FillGap(edits, request, stop).status();
    };
  };
  const int64_t clips = StoredClips();
  const std::vector<std::pair<std::string, Operation>> operations = {
      {"smooth",
       [&](const std::function<bool()>& stop) {
         return server::Smooth(edits, {curve_edit(), {}}, stop).status();
       }},
      {"scale",
       [&](const std::function<bool()>& stop) {
         return server::Scale(edits, {curve_edit(), {}}, stop).status();
       }},
      {"translate",
       [&](const std::function<bool()>& stop) {
         return server::Translate(edits, {curve_edit(), {{(*clip_ids_)[1], 0, 0}}, {}}, stop)
             .status();
       }},
      {"reconstruct",
       [&](const std::function<bool()>& stop) {
         server::ReconstructRequest request{
             "body", range, {.dims = 3, .error_curve = true}, output};
         return server::Reconstruct(edits, request, stop).status();
       }},
      {"fill gap", transition(1000, 1000, 50, 0)},
      {"aligned overlap", transition(1500, 2000, 0, 40)},
      {"blend",
       [&](const std::function<bool()>& stop) {
         server::BlendRequest request;
         request.space = "body";
         request.poses = {{{clip_ids_->front(), 0, 0}, 0, 0}, {{(*clip_ids_)[1], 90, 90}, 1, 1}};
         request.path = {{0, 0}, {1, 1}};
         request.frames_per_segment = 5000;
         request.output = output;
         return server::Blend(edits, request, stop).status();
       }},
      {"interpolate",
       [&](const std::function<bool()>& stop) {
         server::InterpolateRequest request;
         request.space = "body";
         request.from = {clip_ids_->front(), 0, 0};
         request.to = {(*clip_ids_)[1], 90, 90};
         request.options.steps = 5000;
         request.output = output;
         return server::Interpolate(edits, request, stop).status();
       }},
  };
  for (const auto& [name, op] : operations) {
    SCOPED_TRACE(name);
    ExpectStopsAtEveryPoll(op, 4, [&] {
      EXPECT_EQ(StoredClips(), clips + 1);  // the whole run's result
      const absl::StatusOr<storage::ClipPage> page = database_->ListClips({}, "");
      ASSERT_TRUE(page.ok()) << page.status();
      for (const storage::ClipRecord& clip : page->clips) {
        if (clip.name == output.store_name) {
          ASSERT_TRUE(catalog_->DeleteClip(clip.clip_id).ok());
        }
      }
    });
    EXPECT_EQ(StoredClips(), clips);  // none of the stopped runs'
  }
}

TEST_F(DeadlineTest, PoseModelsStopWhileFittedAndWhileDetected) {
  const server::EditContext edits = Edits();
  ExpectStopsAtEveryPoll(
      [&](const std::function<bool()>& stop) {
        server::PoseModelRequest request;
        request.name = "stopped_model";
        request.space = "body";
        request.examples = {{clip_ids_->front(), std::nullopt, std::nullopt},
                            {(*clip_ids_)[1], std::nullopt, std::nullopt}};
        request.options.components = 4;
        request.options.max_iterations = 30;
        request.options.tolerance = 0;
        const absl::Status status = server::CreatePoseModel(edits, request, stop).status();
        if (!status.ok()) {
          EXPECT_TRUE(absl::IsNotFound(database_->GetPoseModel(request.name).status()));
        }
        return status;
      },
      4, [&] { ASSERT_TRUE(server::DeletePoseModel(edits, "stopped_model", {}).ok()); });
  server::PoseModelRequest model;
  model.name = "detected";
  model.space = "body";
  model.examples = {{clip_ids_->front(), 0, 300}};
  model.options.components = 8;
  model.options.dims = 10;
  ASSERT_TRUE(server::CreatePoseModel(edits, model, {}).ok());
  ExpectStopsAtEveryPoll(
      [&](const std::function<bool()>& stop) {
        server::DetectRequest request;
        request.model = "detected";
        request.clip = {(*clip_ids_)[1], std::nullopt, std::nullopt};
        return server::DetectPose(edits, request, stop).status();
      },
      4);
  ASSERT_TRUE(server::DeletePoseModel(edits, "detected", {}).ok());
}

// A curve of these clips is read within one poll's work: a stop already given ends it.
TEST_F(DeadlineTest, CurvesStop) {
  server::CurveRequest request;
  request.space = "body";
  request.clip = {clip_ids_->front(), std::nullopt, std::nullopt};
  StopAfter stop(0);
  EXPECT_TRUE(absl::IsCancelled(
      server::ReadCurve(*registry_, *database_, request, server::AnswerLimit(), stop.function())
          .status()));
  EXPECT_EQ(stop.polls(), 1);
  EXPECT_TRUE(server::ReadCurve(*registry_, *database_, request, server::AnswerLimit(), [] {
                return false;
              }).ok());
}

// The overlap of FillGap is a warp's query: its table is held to a search query's.
TEST_F(DeadlineTest, RefusesAnOverlapWhoseWarpTakesMoreThanTheLongestQuery) {
  server::EditContext edits = Edits();
  edits.max_query_frames = 100;
  server::FillGapRequest request;
  request.space = "body";
  request.first = {clip_ids_->front(), 0, 1000};
  request.second = {(*clip_ids_)[1], 0, 1000};
  request.overlap_s = 5;  // 150 frames at 30 Hz
  StopAfter counter(kNever);
  const absl::Status status = server::FillGap(edits, request, counter.function()).status();
  EXPECT_TRUE(absl::IsInvalidArgument(status)) << status;
  EXPECT_THAT(status.message(), HasSubstr("overlap_s"));
  EXPECT_THAT(status.message(), HasSubstr("--max-query-frames"));
  request.overlap_s = 3;  // 90 frames
  EXPECT_TRUE(server::FillGap(edits, request, counter.function()).ok());
}

}  // namespace
}  // namespace motiondb
