// The SQLite storage's jobs on real files (storage_fixture.h): created, updated, listed and
// counted; interrupted when a process left them unfinished; a propagation's output replaced in
// one transaction.
#include "storage/database.h"

#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/storage_fixture.h"

namespace motiondb::storage {
namespace {

using ::testing::HasSubstr;

TEST_F(StorageTest, JobsAreCreatedUpdatedListedNewestFirstAndPaged) {
  JobRecord job;
  job.parameters_json = R"({"space":"body"})";
  const absl::StatusOr<JobRecord> first = Db().CreateJob(job);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(first->job_id, "job-1");
  EXPECT_EQ(first->state, JobState::kQueued);
  EXPECT_GT(first->created_unix_ms, 0);
  const JobRecord second = *Db().CreateJob(job);
  const JobRecord third = *Db().CreateJob(job);
  EXPECT_EQ(third.job_id, "job-3");

  JobRecord running = *first;
  running.state = JobState::kRunning;
  running.started_unix_ms = 1700000000000;
  running.done = 3;
  running.total = 10;
  running.queries = 3;
  running.queries_skipped = 1;
  ASSERT_TRUE(Db().UpdateJob(running).ok());
  const absl::StatusOr<JobRecord> read = Db().GetJob("job-1");
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->state, JobState::kRunning);
  EXPECT_EQ(read->parameters_json, job.parameters_json);
  EXPECT_EQ(read->done, 3);
  EXPECT_EQ(read->total, 10);
  EXPECT_EQ(read->queries_skipped, 1);
  EXPECT_EQ(read->started_unix_ms, 1700000000000);

  // Newest first, a page at a time, each job once.
  std::vector<std::string> listed;
  Page page{.page_size = 2, .page_token = ""};
  do {
    const absl::StatusOr<JobPage> jobs = Db().ListJobs(page);
    ASSERT_TRUE(jobs.ok()) << jobs.status();
    for (const JobRecord& listed_job : jobs->jobs) listed.push_back(listed_job.job_id);
    page.page_token = jobs->next_page_token;
  } while (!page.page_token.empty());
  EXPECT_EQ(listed, (std::vector<std::string>{third.job_id, second.job_id, "job-1"}));

  // Unknown or malformed ids, a bad page token, a bad kind or a final state.
  for (const std::string id : {"job-99", "job-0", "7", "job-x", ""}) {
    EXPECT_EQ(Db().GetJob(id).status().code(), absl::StatusCode::kNotFound) << id;
  }
  running.job_id = "job-99";
  EXPECT_EQ(Db().UpdateJob(running).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(Db().ListJobs({.page_token = "x"}).status().code(), absl::StatusCode::kInvalidArgument);
  job.kind = "build";
  EXPECT_EQ(Db().CreateJob(job).status().code(), absl::StatusCode::kInvalidArgument);
  job.kind = "propagation";
  job.state = JobState::kSucceeded;
  EXPECT_EQ(Db().CreateJob(job).status().code(), absl::StatusCode::kInvalidArgument);
}

// A database opened with jobs still queued or running was left by a process that died (or
// stopped) first: those jobs are interrupted, the finished ones stay as they were.
TEST_F(StorageTest, JobsAreCountedByState) {
  EXPECT_TRUE(Db().CountJobs()->empty());
  JobRecord job;
  const JobRecord first = *Db().CreateJob(job);
  Db().CreateJob(job).IgnoreError();
  JobRecord failed = *Db().CreateJob(job);
  failed.state = JobState::kFailed;
  failed.error = "why";
  ASSERT_TRUE(Db().UpdateJob(failed).ok());
  JobRecord running = first;
  running.state = JobState::kRunning;
  ASSERT_TRUE(Db().UpdateJob(running).ok());
  const absl::StatusOr<std::map<JobState, int64_t>> counts = Db().CountJobs();
  ASSERT_TRUE(counts.ok()) << counts.status();
  EXPECT_EQ(*counts, (std::map<JobState, int64_t>{
                         {JobState::kQueued, 1}, {JobState::kRunning, 1}, {JobState::kFailed, 1}}));
}

TEST_F(StorageTest, OpenInterruptsTheJobsADeadProcessLeftUnfinished) {
  const JobRecord queued = *Db().CreateJob({});
  JobRecord running = *Db().CreateJob({});
  running.state = JobState::kRunning;
  ASSERT_TRUE(Db().UpdateJob(running).ok());
  JobRecord failed = *Db().CreateJob({});
  failed.state = JobState::kFailed;
  failed.error = "boom";
  failed.finished_unix_ms = 1234;
  ASSERT_TRUE(Db().UpdateJob(failed).ok());
  Close();

  for (const std::string& id : {queued.job_id, running.job_id}) {
    const absl::StatusOr<JobRecord> job = Db().GetJob(id);
    ASSERT_TRUE(job.ok()) << job.status();
    EXPECT_EQ(job->state, JobState::kInterrupted) << id;
    EXPECT_GT(job->finished_unix_ms, 0) << id;
    EXPECT_THAT(job->error, HasSubstr("stopped before the job ended"));
  }
  const JobRecord kept = *Db().GetJob(failed.job_id);
  EXPECT_EQ(kept.state, JobState::kFailed);
  EXPECT_EQ(kept.error, "boom");
  EXPECT_EQ(kept.finished_unix_ms, 1234);
}

TEST_F(StorageSpaceTest, FinishPropagationReplacesItsDescriptorsOutputInOneTransaction) {
  const auto [walk, wave, space_id, manual] = InsertLabelledLibrary();
  EXPECT_EQ(*Db().ManualDescriptors(), (std::vector<std::string>{"kick", "wave"}));

  // The output of one job for `descriptors`: `count` kick labels on the wave clip.
  const auto output = [&](const std::vector<std::string>& descriptors, int count) {
    PropagationOutput out;
    out.job = *Db().CreateJob({});
    out.job.state = JobState::kSucceeded;
    out.space_id = space_id;
    out.descriptors = descriptors;
    for (int i = 0; i < count; ++i) {
      LabelRecord label = Manual(wave, 10 * i, 10 * i + 5, "kick", 0.5);
      label.origin = LabelOrigin::kPropagated;
      label.source_label_id = manual[0];
      label.space_id = space_id;
      label.score = 0.1;
      label.job_id = out.job.job_id;
      out.labels.push_back(label);
    }
    return out;
  };
  const PropagationOutput first = output({"kick"}, 3);
  EXPECT_EQ(*Db().FinishPropagation(first), 3);
  EXPECT_EQ(Db().GetJob(first.job.job_id)->labels_written, 3);
  EXPECT_EQ(Db().GetJob(first.job.job_id)->state, JobState::kSucceeded);

  // A stopped write and a bad label change nothing: neither the labels nor the job.
  PropagationOutput second = output({"kick"}, 2);
  EXPECT_EQ(Db().FinishPropagation(second, {.should_stop = [] { return true; }}).status().code(),
            absl::StatusCode::kCancelled);
  EXPECT_EQ(Db().GetJob(second.job.job_id)->state, JobState::kQueued);
  PropagationOutput bad = second;
  bad.labels[1].descriptor = "wave";
  const absl::Status refused = Db().FinishPropagation(bad).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(refused.message()), HasSubstr("labels[1].descriptor"));
  EXPECT_EQ(Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels.size(), 3u);

  // The re-run replaces the first run's kick labels; manual labels stay; a label whose source
  // was deleted meanwhile is left out.
  EXPECT_EQ(*Db().FinishPropagation(second), 2);
  std::vector<LabelRecord> propagated =
      Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels;
  ASSERT_EQ(propagated.size(), 2u);
  for (const LabelRecord& label : propagated) EXPECT_EQ(label.job_id, second.job.job_id);
  EXPECT_EQ(Db().ListLabels({}, {.origin = LabelOrigin::kManual})->labels.size(), 2u);
  PropagationOutput orphan = output({"kick"}, 2);
  orphan.labels[0].source_label_id = manual[1];
  ASSERT_TRUE(Db().DeleteLabels(std::vector<int64_t>{manual[1]}).ok());
  EXPECT_EQ(*Db().FinishPropagation(orphan), 1);
  EXPECT_EQ(Db().ListLabels({}, {.origin = LabelOrigin::kPropagated})->labels.size(), 1u);

  // A space deleted while the job ran: refused (not a foreign-key error), the job row unchanged.
  PropagationOutput gone = output({"kick"}, 1);
  ASSERT_TRUE(Db().DeleteSpace("body").ok());
  const absl::Status no_space = Db().FinishPropagation(gone).status();
  EXPECT_EQ(no_space.code(), absl::StatusCode::kNotFound) << no_space;
  EXPECT_THAT(std::string(no_space.message()), HasSubstr("deleted while the job ran"));
  EXPECT_EQ(Db().GetJob(gone.job.job_id)->state, JobState::kQueued);
}

}  // namespace
}  // namespace motiondb::storage
