// Propagation jobs on the real server binary (server_fixture.h): labels spread to similar
// ranges, re-runs, learned metrics, bad requests, running jobs cancelled and watched, a kill
// during a job.
#include <signal.h>
#include <cstring>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "tests/server_fixture.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;
using testing::SyntheticAction;
using testing::SyntheticSegment;

bool Overlap(int64_t first, int64_t last, const SyntheticSegment& segment) {
  return first <= segment.last_frame && last >= segment.first_frame;
}

TEST_F(ServerTest, PropagationLabelsSimilarRangesAndReRunsReplaceItsOutput) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  // Two right-arm raises labelled by hand, and a shrug.
  std::vector<const SyntheticSegment*> raises, shrugs;
  for (const SyntheticSegment& segment : Humanoid().segments) {
    (segment.action == SyntheticAction::kRightArmRaise ? raises : shrugs).push_back(&segment);
  }
  ASSERT_GE(raises.size(), 4u);
  std::vector<v1::NewLabel> given;
  for (const SyntheticSegment* raise : {raises[0], raises[1]}) {
    given.push_back(
        FrameLabel(ids[raise->clip], raise->first_frame, raise->last_frame, "raise-right", 1.0));
  }
  given.push_back(FrameLabel(ids[Humanoid().segments.back().clip],
                             Humanoid().segments.back().first_frame,
                             Humanoid().segments.back().last_frame, "other", 0.5));
  const std::vector<v1::Label> manual = AddLabelsOrFail(client, given);
  ASSERT_EQ(manual.size(), 3u);

  // Watched to its end: the first message is the job as it was, the last its end.
  const v1::Job started = StartOrFail(client, Propagation({"raise-right"}));
  EXPECT_THAT(started.job_id(), ::testing::StartsWith("job-"));
  EXPECT_EQ(started.space(), "body");
  EXPECT_THAT(started.descriptor_names(), ::testing::ElementsAre("raise-right"));
  v1::WatchJobRequest watch;
  watch.set_job_id(started.job_id());
  auto context = client.Context();
  auto reader = client.jobs().WatchJob(context.get(), watch);
  std::vector<v1::Job> seen;
  for (v1::Job job; reader->Read(&job);) seen.push_back(job);
  ASSERT_TRUE(reader->Finish().ok());
  // One message at least (a fast job may have ended before the watch began); the last final.
  ASSERT_FALSE(seen.empty());
  const v1::Job& ended = seen.back();
  ASSERT_EQ(ended.state(), v1::JOB_STATE_SUCCEEDED) << ended.error();
  for (size_t i = 0; i + 1 < seen.size(); ++i) EXPECT_FALSE(Ended(seen[i]));
  EXPECT_EQ(ended.total(), 2);
  EXPECT_EQ(ended.done(), 2);
  EXPECT_EQ(ended.queries(), 2);
  EXPECT_GT(ended.labels_written(), 0);
  EXPECT_GT(ended.finished_unix_ms(), 0);

  // Found: propagated ranges with their source, job, space and score, values in (0, 1], no two
  // overlapping by more than half, on other raises too, and none of the "other" descriptor.
  v1::FindLabelsRequest find;
  find.set_descriptor_name("raise-right");
  find.set_page_size(1000);
  v1::FindLabelsResponse found;
  ASSERT_TRUE(client.labels().FindLabels(client.Context().get(), find, &found).ok());
  std::vector<v1::Label> propagated;
  for (const v1::Label& label : found.labels()) {
    if (label.origin() == v1::LABEL_ORIGIN_PROPAGATED) propagated.push_back(label);
  }
  EXPECT_EQ(static_cast<int64_t>(propagated.size()), ended.labels_written());
  EXPECT_EQ(Propagated(client).size(), propagated.size());
  int on_other_raises = 0;
  for (const v1::Label& label : propagated) {
    EXPECT_GT(label.value(), 0);
    EXPECT_LE(label.value(), 1);
    EXPECT_EQ(label.job_id(), started.job_id());
    EXPECT_EQ(label.space(), "body");
    EXPECT_THAT(label.source_label_id(),
                ::testing::AnyOf(manual[0].label_id(), manual[1].label_id()));
    EXPECT_GE(label.score(), 0);
    for (size_t r = 2; r < raises.size(); ++r) {
      if (ids[raises[r]->clip] == label.clip_id() &&
          Overlap(label.first_frame(), label.last_frame(), *raises[r])) {
        ++on_other_raises;
        break;
      }
    }
    for (const v1::Label& other : propagated) {
      if (other.label_id() == label.label_id() || other.clip_id() != label.clip_id()) continue;
      const int64_t shared = std::min(label.last_frame(), other.last_frame()) -
                             std::max(label.first_frame(), other.first_frame()) + 1;
      // Of the shorter one: a long range around a short stronger one is not kept beside it.
      EXPECT_LE(2 * shared, std::min(label.last_frame() - label.first_frame() + 1,
                                     other.last_frame() - other.first_frame() + 1));
    }
  }
  EXPECT_GE(on_other_raises, 2);
  // Strongest first: the best propagated label is the closest (the factor falls with score).
  EXPECT_LE(propagated.front().score(), propagated.back().score());

  // A re-run replaces the output: the same labels, of the new job; the manual ones unchanged.
  const v1::Job again = PollJob(client, StartOrFail(client, Propagation({"raise-right"})).job_id());
  ASSERT_EQ(again.state(), v1::JOB_STATE_SUCCEEDED) << again.error();
  EXPECT_EQ(again.labels_written(), ended.labels_written());
  const std::vector<v1::Label> replaced = Propagated(client);
  ASSERT_EQ(replaced.size(), propagated.size());
  for (const v1::Label& label : replaced) EXPECT_EQ(label.job_id(), again.job_id());
  v1::ListLabelsRequest list;
  list.set_origin(v1::LABEL_ORIGIN_MANUAL);
  v1::ListLabelsResponse kept;
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), list, &kept).ok());
  ASSERT_EQ(kept.labels_size(), 3);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(kept.labels(i).ShortDebugString(), manual[i].ShortDebugString());

  // Listed newest first; a finished job cannot be cancelled.
  v1::ListJobsRequest jobs_request;
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(client.jobs().ListJobs(client.Context().get(), jobs_request, &jobs).ok());
  ASSERT_EQ(jobs.jobs_size(), 2);
  EXPECT_EQ(jobs.jobs(0).job_id(), again.job_id());
  EXPECT_EQ(jobs.jobs(1).job_id(), started.job_id());
  v1::CancelJobRequest cancel;
  cancel.set_job_id(started.job_id());
  v1::Job cancelled;
  const grpc::Status refused = client.jobs().CancelJob(client.Context().get(), cancel, &cancelled);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(refused.error_message(), HasSubstr("succeeded"));
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.JobService/StartPropagation OK "));

  // Both descriptors with rival_share 1: of two ranges of the two descriptors sharing more than
  // half of the shorter one, at most the stronger is written, and fewer labels than without it.
  const v1::Job both =
      PollJob(client, StartOrFail(client, Propagation({"other", "raise-right"})).job_id());
  ASSERT_EQ(both.state(), v1::JOB_STATE_SUCCEEDED) << both.error();
  v1::StartPropagationRequest exclusive = Propagation({"other", "raise-right"});
  exclusive.set_rival_share(1);
  const v1::Job uncontested = PollJob(client, StartOrFail(client, exclusive).job_id());
  ASSERT_EQ(uncontested.state(), v1::JOB_STATE_SUCCEEDED) << uncontested.error();
  EXPECT_GT(uncontested.labels_written(), 0);
  EXPECT_LT(uncontested.labels_written(), both.labels_written());
  const std::vector<v1::Label> written = Propagated(client);
  ASSERT_EQ(static_cast<int64_t>(written.size()), uncontested.labels_written());
  for (const v1::Label& label : written) {
    for (const v1::Label& other : written) {
      if (other.descriptor_name() == label.descriptor_name() ||
          other.clip_id() != label.clip_id()) {
        continue;
      }
      const int64_t shared = std::min(label.last_frame(), other.last_frame()) -
                             std::max(label.first_frame(), other.first_frame()) + 1;
      EXPECT_LE(2 * shared, std::min(label.last_frame() - label.first_frame() + 1,
                                     other.last_frame() - other.first_frame() + 1));
    }
  }
}

// A space whose search metric is learned from the manual labels: refused with a clear error
// while no descriptor labels two clips or its shrink is out of range; then built, its report
// saying what it was fitted on, its curves the projection as in a space without it, its
// searches finding the labelled action again with explanations that add up, and all of it as
// before after a restart (the transform stored with the space).
TEST_F(ServerTest, ASpaceSearchesInAMetricLearnedFromTheLabels) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  // What the restarted server must answer alike: a stored and an uploaded query (the latter
  // projected anew in the space as read back), and a curve (turned back through its inverse).
  v1::SearchRequest query, uploaded;
  v1::SearchResponse before, uploaded_before;
  v1::GetCurveRequest curve_request;
  v1::GetCurveResponse learned_curve;
  v1::Space learned;
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    CreateHumanoidSpace(client);
    v1::CreateSpaceRequest request;
    request.set_name("learned");
    request.mutable_learned_metric();
    grpc::Status status = client.CreateSpace(request, &learned);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_EQ(status.error_message(),
              "learned_metric: needs one descriptor labelled (manual labels, value >= 0.5) on at "
              "least two clips of the space's skeleton; of its 0 such labels, no descriptor is on "
              "two clips");
    request.mutable_learned_metric()->set_shrink(1);
    status = client.CreateSpace(request, &learned);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(status.error_message(), "learned_metric.shrink: 1 is outside [0, 1)");

    // Every action labelled by its kind (the script's kinds fall on several clips), and one weak
    // label that is no example.
    std::vector<v1::NewLabel> given;
    for (const SyntheticSegment& segment : Humanoid().segments) {
      given.push_back(FrameLabel(ids[segment.clip], segment.first_frame, segment.last_frame,
                                 absl::StrCat("action-", static_cast<int>(segment.action))));
    }
    given.push_back(FrameLabel(ids[0], std::nullopt, std::nullopt, "action-0", 0.2));
    AddLabelsOrFail(client, given);

    request.mutable_learned_metric()->clear_shrink();
    status = client.CreateSpace(request, &learned);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_TRUE(learned.report().has_learned_metric());
    EXPECT_EQ(learned.report().learned_metric().examples(), static_cast<int64_t>(given.size()) - 1);
    EXPECT_EQ(learned.report().learned_metric().descriptors(), 4);
    EXPECT_EQ(learned.report().learned_metric().shrink(), 0.95);

    // The curve is the projection, the same as the plain space's (one training set).
    const SyntheticSegment& raise = FirstRaise();
    curve_request.mutable_clip()->set_clip_id(ids[raise.clip]);
    curve_request.set_dims(5);
    v1::GetCurveResponse plain_curve;
    curve_request.set_space("body");
    ASSERT_TRUE(client.spaces().GetCurve(client.Context().get(), curve_request, &plain_curve).ok());
    curve_request.set_space("learned");
    ASSERT_TRUE(
        client.spaces().GetCurve(client.Context().get(), curve_request, &learned_curve).ok());
    ASSERT_EQ(learned_curve.coordinates().size(), plain_curve.coordinates().size());
    std::vector<float> plain(plain_curve.coordinates().size() / 4), in_learned(plain.size());
    std::memcpy(plain.data(), plain_curve.coordinates().data(), 4 * plain.size());
    std::memcpy(in_learned.data(), learned_curve.coordinates().data(), 4 * plain.size());
    for (size_t i = 0; i < plain.size(); ++i) ASSERT_NEAR(in_learned[i], plain[i], 1e-4) << i;

    query = ClipQuery("learned", ids[raise.clip], raise.first_frame, raise.last_frame);
    query.set_explain(true);
    status = client.Search(query, &before);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_GE(before.results_size(), 3);
    EXPECT_EQ(before.results(0).clip_id(), ids[raise.clip]);  // itself
    // Explained in the space's own metric (tests/search_explanation_test.cc checks the split).
    for (const v1::SearchResult& r : before.results()) EXPECT_TRUE(r.has_explanation());
    uploaded = query;
    uploaded.mutable_bvh()->set_bvh(BvhText(Humanoid().clips[raise.clip]));
    uploaded.mutable_bvh()->set_first_frame(raise.first_frame);
    uploaded.mutable_bvh()->set_last_frame(raise.last_frame);
    status = client.Search(uploaded, &uploaded_before);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_GE(uploaded_before.results_size(), 3);
  }
  EXPECT_EQ(server->Stop(SIGTERM), 0);

  server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  v1::GetSpaceRequest get;
  get.set_name("learned");
  v1::Space after_restart;
  ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &after_restart).ok());
  EXPECT_EQ(after_restart.report().SerializeAsString(), learned.report().SerializeAsString());
  v1::SearchResponse after;
  ASSERT_TRUE(client.Search(query, &after).ok());
  ExpectSameResults(after, before);
  ASSERT_TRUE(client.Search(uploaded, &after).ok());
  ExpectSameResults(after, uploaded_before);
  v1::GetCurveResponse curve_after;
  ASSERT_TRUE(client.spaces().GetCurve(client.Context().get(), curve_request, &curve_after).ok());
  EXPECT_EQ(curve_after.coordinates(), learned_curve.coordinates());
}

TEST_F(ServerTest, BadPropagationsGetTheirStatusCodes) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t walk = client.IngestOrFail("walk.bvh", BvhText(ChainClip()));
  v1::CreateSpaceRequest create;
  create.set_name("body");
  v1::Space space;
  ASSERT_TRUE(client.CreateSpace(create, &space).ok());

  const auto start = [&](const v1::StartPropagationRequest& request) {
    v1::Job job;
    return client.jobs().StartPropagation(client.Context().get(), request, &job);
  };
  // No descriptors given and no manual label: there is nothing to propagate (refused, rather
  // than a job that does nothing).
  grpc::Status status = start(Propagation({}));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("no manual label"));
  v1::StartPropagationRequest request = Propagation({"step"});
  request.set_space("nowhere");
  EXPECT_EQ(start(request).error_code(), grpc::StatusCode::NOT_FOUND);
  for (const double share : {0.0, -0.5, 1.5}) {
    request = Propagation({"step"});
    request.set_rival_share(share);
    status = start(request);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << share;
    EXPECT_THAT(status.error_message(), HasSubstr("rival_share"));
  }
  request = Propagation({"step", ""});
  status = start(request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("descriptors[1]"));
  // Descriptors no label could carry: too long, a control character.
  for (const std::string& bad : {std::string(257, 'd'), std::string("st\x1b[2Jep")}) {
    status = start(Propagation({"step", bad}));
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("descriptors[1]"));
  }
  request = Propagation({"step"});
  request.mutable_search()->set_max_results(0);
  status = start(request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("max_results"));
  request = Propagation({"step"});
  request.mutable_search()->mutable_clip()->set_clip_id(walk);
  status = start(request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("search.query"));

  // Unknown jobs.
  for (const std::string id : {"job-42", "nonsense"}) {
    v1::GetJobRequest get;
    get.set_job_id(id);
    v1::Job job;
    EXPECT_EQ(client.jobs().GetJob(client.Context().get(), get, &job).error_code(),
              grpc::StatusCode::NOT_FOUND);
    v1::CancelJobRequest cancel;
    cancel.set_job_id(id);
    EXPECT_EQ(client.jobs().CancelJob(client.Context().get(), cancel, &job).error_code(),
              grpc::StatusCode::NOT_FOUND);
    v1::WatchJobRequest watch;
    watch.set_job_id(id);
    auto context = client.Context();
    auto reader = client.jobs().WatchJob(context.get(), watch);
    EXPECT_FALSE(reader->Read(&job));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::NOT_FOUND);
  }
  // Given descriptors without manual labels: a job that finds nothing and writes nothing.
  const v1::Job job = PollJob(client, StartOrFail(client, Propagation({"step"})).job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error();
  EXPECT_EQ(job.total(), 0);
  EXPECT_EQ(job.labels_written(), 0);
  v1::ListJobsRequest list;
  list.set_page_size(-1);
  v1::ListJobsResponse jobs;
  EXPECT_EQ(client.jobs().ListJobs(client.Context().get(), list, &jobs).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

bool Running(const v1::Job& job) {
  return Ended(job) || (job.state() == v1::JOB_STATE_RUNNING && job.done() >= 1);
}

TEST_F(ServerTest, RunningJobsRefuseOverlapsAreCancelledAndWatchedOutsideTheCallGate) {
  // One call at a time: a watch that held its place would block every other call. The job
  // waits after its first label until cancelled, so it is seen running on any machine.
  ServerProcess* server = StartServer({"--threads", "1", "--test-job-pause-after", "1"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  LabelManyRanges(client, ids, 20);
  AddLabelsOrFail(client, {FrameLabel(ids[0], 0, 50, "calm", 1.0)});
  const v1::Job started = StartOrFail(client, Propagation({"long", "calm"}));

  std::vector<v1::Job> watched;
  grpc::Status watch_status;
  std::thread watcher([&] {
    v1::WatchJobRequest watch;
    watch.set_job_id(started.job_id());
    auto context = client.Context(std::chrono::milliseconds(120000));
    auto reader = client.jobs().WatchJob(context.get(), watch);
    for (v1::Job job; reader->Read(&job);) watched.push_back(job);
    watch_status = reader->Finish();
  });
  const v1::Job running = PollJob(client, started.job_id(), Running);
  ASSERT_EQ(running.state(), v1::JOB_STATE_RUNNING);

  // A second job for one of its descriptors is refused, naming it; another descriptor runs.
  v1::Job second;
  const grpc::Status refused =
      client.jobs().StartPropagation(client.Context().get(), Propagation({"calm"}), &second);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(refused.error_message(), HasSubstr(started.job_id()));

  v1::CancelJobRequest cancel;
  cancel.set_job_id(started.job_id());
  v1::Job cancelled;
  const grpc::Status status = client.jobs().CancelJob(client.Context().get(), cancel, &cancelled);
  ASSERT_TRUE(status.ok()) << status.error_message();
  // Answered at once, the job as it is: still running (it stops at its next check) or ended.
  EXPECT_THAT(cancelled.state(), ::testing::AnyOf(v1::JOB_STATE_RUNNING, v1::JOB_STATE_CANCELLED));
  const v1::Job stopped = PollJob(client, started.job_id());
  EXPECT_EQ(stopped.state(), v1::JOB_STATE_CANCELLED);
  EXPECT_LT(stopped.done(), stopped.total());
  // A second cancel finds it ended.
  const grpc::Status again = client.jobs().CancelJob(client.Context().get(), cancel, &cancelled);
  EXPECT_EQ(again.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(again.error_message(), HasSubstr("cancelled"));
  watcher.join();
  EXPECT_TRUE(watch_status.ok()) << watch_status.error_message();
  ASSERT_FALSE(watched.empty());
  EXPECT_EQ(watched.back().state(), v1::JOB_STATE_CANCELLED);
  EXPECT_TRUE(Propagated(client).empty());
  // Once it ended, the descriptor is free again.
  EXPECT_EQ(PollJob(client, StartOrFail(client, Propagation({"calm"})).job_id()).state(),
            v1::JOB_STATE_SUCCEEDED);
}

TEST_F(ServerTest, KillDuringAJobLeavesItInterruptedWithoutOutputAndItRunsAgain) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  std::string job_id;
  int64_t earlier = 0;  // labels of the first, complete run
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    CreateHumanoidSpace(client);
    LabelManyRanges(client, ids, 400);
    const v1::Job first = PollJob(client, StartOrFail(client, Propagation({"long"})).job_id());
    ASSERT_EQ(first.state(), v1::JOB_STATE_SUCCEEDED) << first.error();
    earlier = first.labels_written();
    ASSERT_GT(earlier, 0);
  }
  // Again with the job held after its first label, so that the kill finds it running on any
  // machine.
  EXPECT_EQ(server->Stop(SIGTERM), 0);
  server = StartServer({"--test-job-pause-after", "1"});
  ASSERT_NE(server, nullptr);
  {
    Client client(testing::InsecureChannel(server->address()));
    job_id = StartOrFail(client, Propagation({"long"})).job_id();
    ASSERT_EQ(PollJob(client, job_id, Running).state(), v1::JOB_STATE_RUNNING);
  }
  EXPECT_EQ(server->Stop(SIGKILL), 128 + SIGKILL);

  server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  v1::GetJobRequest get;
  get.set_job_id(job_id);
  v1::Job job;
  ASSERT_TRUE(client.jobs().GetJob(client.Context().get(), get, &job).ok());
  EXPECT_EQ(job.state(), v1::JOB_STATE_INTERRUPTED);
  EXPECT_THAT(job.error(), HasSubstr("stopped"));
  // The first run's output, whole; nothing of the cut-off run.
  const std::vector<v1::Label> labels = Propagated(client);
  EXPECT_EQ(static_cast<int64_t>(labels.size()), earlier);
  for (const v1::Label& label : labels) EXPECT_NE(label.job_id(), job_id);
  const v1::Job again = PollJob(client, StartOrFail(client, Propagation({"long"})).job_id());
  EXPECT_EQ(again.state(), v1::JOB_STATE_SUCCEEDED) << again.error();
  EXPECT_EQ(again.labels_written(), earlier);
}

}  // namespace
}  // namespace motiondb
