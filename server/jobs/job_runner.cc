#include "server/jobs/job_runner.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "util/parallel_for.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// How often a running job's progress is written to its row: often enough for a listing after a
// crash to show roughly how far it got, rarely enough that the writes (each synced to disk)
// cost the job nothing to speak of. Watchers and GetJob see every change at once, from memory.
constexpr std::chrono::seconds kProgressWriteInterval{1};

// See the class comment: the worker yields the cores to the threads serving calls.
void LowerThisThreadsPriority() {
  const pid_t thread = ::gettid();
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, thread);
  if (errno != 0) return;
  // Failing leaves the job at the server's priority, slower for searches but still correct.
  (void)::setpriority(PRIO_PROCESS, thread, std::min(19, nice + kWorkerNiceIncrement));
}

// Writes `record`'s row; a failure is logged (the job's memory copy stays right, and a row left
// queued or running becomes interrupted at the next open).
void WriteRow(storage::Database& database, const storage::JobRecord& record) {
  const absl::Status written = database.UpdateJob(record);
  if (!written.ok()) {
    // One write of the whole line, so that it does not interleave with the request log's.
    const std::string line =
        absl::StrCat("motiondb-server: job ", record.job_id, ": writing its row (",
                     storage::JobStateName(record.state), ") failed: ", written.message(), "\n");
    std::fputs(line.c_str(), stderr);
  }
}

}  // namespace

bool SameProgress(const storage::JobRecord& a, const storage::JobRecord& b) {
  return a.state == b.state && a.done == b.done && a.total == b.total && a.queries == b.queries &&
         a.queries_skipped == b.queries_skipped && a.labels_written == b.labels_written;
}

JobRunner::JobRunner(storage::Database& database, const IndexRegistry& registry,
                     const SearchRunner& runner, const JobRunnerOptions& options)
    : database_(database), registry_(registry), runner_(runner), options_(options) {
  worker_ = std::thread([this] { Work(); });  // once every member exists
}

JobRunner::~JobRunner() { Stop(); }

absl::StatusOr<storage::JobRecord> JobRunner::StartPropagation(PropagationRequest request) {
  MOTIONDB_ASSIGN_OR_RETURN(PropagationRequest resolved,
                            ResolvePropagation(database_, registry_, std::move(request)));
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) return absl::UnavailableError("the server is stopping; start the job again");
  if (const Live* running = Conflict(resolved.descriptors)) {
    return absl::FailedPreconditionError(absl::StrCat(
        "descriptors: ", running->record.job_id, " (", storage::JobStateName(running->record.state),
        ") propagates some of them already; wait for it to end or cancel it"));
  }
  if (static_cast<int>(queue_.size()) >= kMaxQueuedJobs) {
    return absl::ResourceExhaustedError(
        absl::StrCat(queue_.size(), " jobs are waiting, the most the server queues"));
  }
  storage::JobRecord job;
  job.parameters_json = ParametersJson(resolved);
  // Written under the lock, so that a second start cannot pass the conflict check meanwhile.
  MOTIONDB_ASSIGN_OR_RETURN(job, database_.CreateJob(job));
  live_[job.job_id] = Live{job, std::move(resolved)};
  queue_.push_back(job.job_id);
  changed_.notify_all();
  return job;
}

const JobRunner::Live* JobRunner::Conflict(const std::vector<std::string>& descriptors) const {
  for (const auto& [job_id, live] : live_) {
    for (const std::string& descriptor : live.request.descriptors) {
      if (std::find(descriptors.begin(), descriptors.end(), descriptor) != descriptors.end()) {
        return &live;
      }
    }
  }
  return nullptr;
}

const storage::JobRecord* JobRunner::FindLocked(const std::string& job_id) const {
  if (const auto live = live_.find(job_id); live != live_.end()) return &live->second.record;
  for (const storage::JobRecord& ended : ended_) {
    if (ended.job_id == job_id) return &ended;
  }
  return nullptr;
}

void JobRunner::EndLocked(const storage::JobRecord& record) {
  live_.erase(record.job_id);
  if (running_id_ == record.job_id) running_id_.clear();
  ended_.push_back(record);
  while (ended_.size() > kRecentlyEndedJobs) ended_.pop_front();
  changed_.notify_all();
}

bool JobRunner::IsLive(const std::string& job_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return live_.contains(job_id);
}

absl::StatusOr<storage::JobRecord> JobRunner::Get(const std::string& job_id) const {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const storage::JobRecord* job = FindLocked(job_id)) return *job;
  }
  return database_.GetJob(job_id);
}

absl::StatusOr<storage::JobPage> JobRunner::List(const PageRequest& page) const {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::Page storage_page, StoragePage(page));
  MOTIONDB_ASSIGN_OR_RETURN(storage::JobPage jobs, database_.ListJobs(storage_page));
  std::lock_guard<std::mutex> lock(mutex_);
  for (storage::JobRecord& job : jobs.jobs) {
    if (const storage::JobRecord* known = FindLocked(job.job_id)) job = *known;
  }
  return jobs;
}

absl::StatusOr<storage::JobRecord> JobRunner::Cancel(const std::string& job_id) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto live = live_.find(job_id);
  if (live == live_.end()) {
    const storage::JobRecord* ended = FindLocked(job_id);
    std::optional<storage::JobRecord> known;
    if (ended != nullptr) known = *ended;
    lock.unlock();
    if (!known) {
      MOTIONDB_ASSIGN_OR_RETURN(known, database_.GetJob(job_id));
    }
    return absl::FailedPreconditionError(
        absl::StrCat(job_id, " has already ended (", storage::JobStateName(known->state), ")"));
  }
  if (const auto queued = std::find(queue_.begin(), queue_.end(), job_id); queued != queue_.end()) {
    queue_.erase(queued);
    storage::JobRecord record = live->second.record;
    record.state = storage::JobState::kCancelled;
    record.finished_unix_ms = absl::ToUnixMillis(absl::Now());
    EndLocked(record);
    lock.unlock();
    WriteRow(database_, record);
    return record;
  }
  // Live and not queued: the running job (running_id_ is set in the same locked step that takes
  // a job off the queue, and cleared in the one that ends it). Only that job is stopped.
  if (job_id == running_id_) {
    stop_running_ = true;
    changed_.notify_all();  // wakes a job held by options_.test_pause_after
  }
  return live->second.record;
}

absl::StatusOr<storage::JobRecord> JobRunner::WaitForChange(
    const std::string& job_id, const storage::JobRecord& seen,
    std::chrono::milliseconds max_wait) const {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, max_wait, [&] {
      const auto live = live_.find(job_id);
      return live == live_.end() || !SameProgress(live->second.record, seen);
    });
    if (const storage::JobRecord* job = FindLocked(job_id)) return *job;
  }
  return database_.GetJob(job_id);
}

void JobRunner::RequestStop() {
  std::vector<storage::JobRecord> queued;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    stop_running_ = true;
    for (const std::string& job_id : queue_) {
      storage::JobRecord record = live_.at(job_id).record;
      record.state = storage::JobState::kInterrupted;
      record.error = "the server stopped before the job ran";
      record.finished_unix_ms = absl::ToUnixMillis(absl::Now());
      queued.push_back(record);
    }
    queue_.clear();
    changed_.notify_all();
  }
  for (const storage::JobRecord& record : queued) Finish(record);
}

void JobRunner::Stop() {
  RequestStop();
  if (worker_.joinable()) worker_.join();
}

void JobRunner::Work() {
  LowerThisThreadsPriority();
  while (true) {
    std::string job_id;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job_id = queue_.front();
      queue_.pop_front();
      running_id_ = job_id;
      stop_running_ = false;
    }
    Run(job_id);
  }
}

void JobRunner::Finish(const storage::JobRecord& record) {
  // Ended in memory first, so that no read sees the job live once its end is decided; a row
  // that cannot be written is logged, and becomes interrupted at the next open.
  {
    std::lock_guard<std::mutex> lock(mutex_);
    EndLocked(record);
  }
  WriteRow(database_, record);
}

void JobRunner::Run(const std::string& job_id) {
  storage::JobRecord record;
  PropagationRequest request;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Live& live = live_.at(job_id);
    live.record.state = storage::JobState::kRunning;
    live.record.started_unix_ms = absl::ToUnixMillis(absl::Now());
    record = live.record;
    request = live.request;
    changed_.notify_all();
  }
  WriteRow(database_, record);
  auto last_write = std::chrono::steady_clock::now();
  const auto on_progress = [&](const PropagationProgress& progress) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      storage::JobRecord& live = live_.at(job_id).record;
      live.done = progress.done;
      live.total = progress.total;
      live.queries = progress.queries;
      live.queries_skipped = progress.skipped;
      record = live;
      changed_.notify_all();
    }
    if (std::chrono::steady_clock::now() - last_write >= kProgressWriteInterval) {
      last_write = std::chrono::steady_clock::now();
      WriteRow(database_, record);
    }
    if (options_.test_pause_after >= 0 && progress.done >= options_.test_pause_after &&
        progress.done < progress.total) {
      WriteRow(database_, record);  // its progress on disk too, for a test that kills the server
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || stop_running_.load(); });
    }
  };
  absl::StatusOr<storage::PropagationOutput> output = RunPropagation(
      database_, registry_, runner_, scales_, request, job_id, ThreadsFor(options_.threads),
      [this] { return stop_running_.load(std::memory_order_relaxed); }, on_progress);
  record.finished_unix_ms = absl::ToUnixMillis(absl::Now());
  if (stop_running_) {
    std::lock_guard<std::mutex> lock(mutex_);
    record.state = stopping_ ? storage::JobState::kInterrupted : storage::JobState::kCancelled;
    if (stopping_) record.error = "the server stopped before the job ended";
  } else if (!output.ok()) {
    record.state = storage::JobState::kFailed;
    record.error = std::string(output.status().message());
  } else {
    record.state = storage::JobState::kSucceeded;
    output->job = record;
    // The labels and the job's final row in one transaction; FinishPropagation sets the count.
    const absl::StatusOr<int64_t> written = database_.FinishPropagation(*output);
    if (written.ok()) {
      record.labels_written = *written;
      std::lock_guard<std::mutex> lock(mutex_);
      EndLocked(record);
      return;
    }
    record.state = storage::JobState::kFailed;
    record.error = absl::StrCat("writing the labels: ", written.status().message());
  }
  Finish(record);
}

}  // namespace motiondb::server
