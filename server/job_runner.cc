#include "server/job_runner.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <utility>

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// How often a running job's progress is written to its row: often enough for a listing after a
// crash to show roughly how far it got, rarely enough that the writes (each synced to disk)
// cost the job nothing to speak of. Watchers and GetJob see every change at once, from memory.
constexpr std::chrono::seconds kProgressWriteInterval{1};
// How long Cancel waits for a running job to notice.
constexpr std::chrono::seconds kCancelWait{30};

int64_t NowUnixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// See the class comment: the worker yields the cores to the threads serving calls.
void LowerThisThreadsPriority() {
  const pid_t thread = ::gettid();
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, thread);
  if (errno != 0) return;
  // Failing leaves the job at the server's priority, slower for searches but still correct.
  (void)::setpriority(PRIO_PROCESS, thread, std::min(19, nice + kWorkerNiceIncrement));
}

const char* StateName(storage::JobState state) {
  static constexpr const char* kNames[] = {"queued", "running",   "succeeded",
                                           "failed", "cancelled", "interrupted"};
  return kNames[static_cast<int>(state)];
}

}  // namespace

bool SameProgress(const storage::JobRecord& a, const storage::JobRecord& b) {
  return a.state == b.state && a.done == b.done && a.total == b.total && a.queries == b.queries &&
         a.queries_skipped == b.queries_skipped && a.labels_written == b.labels_written;
}

JobRunner::JobRunner(storage::Database& database, const IndexRegistry& registry,
                     const SearchRunner& runner)
    : database_(database), registry_(registry), runner_(runner), worker_([this] { Work(); }) {}

JobRunner::~JobRunner() { Stop(); }

absl::StatusOr<storage::JobRecord> JobRunner::StartPropagation(PropagationRequest request) {
  MOTIONDB_ASSIGN_OR_RETURN(PropagationRequest resolved,
                            ResolvePropagation(database_, registry_, std::move(request)));
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) return absl::UnavailableError("the server is stopping; start the job again");
  if (const Live* running = Conflict(resolved.descriptors)) {
    return absl::FailedPreconditionError(absl::StrCat(
        "descriptors: ", running->record.job_id, " (", StateName(running->record.state),
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

absl::StatusOr<storage::JobRecord> JobRunner::Get(const std::string& job_id) const {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const auto live = live_.find(job_id); live != live_.end()) return live->second.record;
  }
  return database_.GetJob(job_id);
}

absl::StatusOr<storage::JobPage> JobRunner::List(const PageRequest& page) const {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::Page storage_page, StoragePage(page));
  MOTIONDB_ASSIGN_OR_RETURN(storage::JobPage jobs, database_.ListJobs(storage_page));
  std::lock_guard<std::mutex> lock(mutex_);
  for (storage::JobRecord& job : jobs.jobs) {
    if (const auto live = live_.find(job.job_id); live != live_.end()) job = live->second.record;
  }
  return jobs;
}

absl::StatusOr<storage::JobRecord> JobRunner::Cancel(const std::string& job_id) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto live = live_.find(job_id);
  if (live == live_.end()) {
    lock.unlock();
    MOTIONDB_ASSIGN_OR_RETURN(const storage::JobRecord job, database_.GetJob(job_id));
    return absl::FailedPreconditionError(
        absl::StrCat(job_id, " has already ended (", StateName(job.state), ")"));
  }
  if (const auto queued = std::find(queue_.begin(), queue_.end(), job_id); queued != queue_.end()) {
    queue_.erase(queued);
    storage::JobRecord record = live->second.record;
    record.state = storage::JobState::kCancelled;
    record.finished_unix_ms = NowUnixMs();
    lock.unlock();
    Finish(record);
    return record;
  }
  stop_running_ = true;  // the job is live and not queued: it is the running one
  changed_.wait_for(lock, kCancelWait, [&] { return !live_.contains(job_id); });
  lock.unlock();
  return Get(job_id);
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
    if (const auto live = live_.find(job_id); live != live_.end()) return live->second.record;
  }
  return database_.GetJob(job_id);
}

void JobRunner::Stop() {
  std::vector<storage::JobRecord> queued;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    stop_running_ = true;
    for (const std::string& job_id : queue_) {
      storage::JobRecord record = live_.at(job_id).record;
      record.state = storage::JobState::kInterrupted;
      record.error = "the server stopped before the job ran";
      record.finished_unix_ms = NowUnixMs();
      queued.push_back(record);
    }
    queue_.clear();
    changed_.notify_all();
  }
  for (const storage::JobRecord& record : queued) Finish(record);
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
      stop_running_ = false;
    }
    Run(job_id);
  }
}

void JobRunner::Finish(const storage::JobRecord& record) {
  // A row that cannot be written stays running, and becomes interrupted at the next open.
  (void)database_.UpdateJob(record);
  std::lock_guard<std::mutex> lock(mutex_);
  live_.erase(record.job_id);
  changed_.notify_all();
}

void JobRunner::Run(const std::string& job_id) {
  storage::JobRecord record;
  PropagationRequest request;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Live& live = live_.at(job_id);
    live.record.state = storage::JobState::kRunning;
    live.record.started_unix_ms = NowUnixMs();
    record = live.record;
    request = live.request;
    changed_.notify_all();
  }
  (void)database_.UpdateJob(record);
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
      (void)database_.UpdateJob(record);
    }
  };
  absl::StatusOr<storage::PropagationOutput> output = RunPropagation(
      database_, registry_, runner_, request, job_id,
      [this] { return stop_running_.load(std::memory_order_relaxed); }, on_progress);
  record.finished_unix_ms = NowUnixMs();
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
      std::lock_guard<std::mutex> lock(mutex_);
      live_.erase(job_id);
      changed_.notify_all();
      return;
    }
    record.state = storage::JobState::kFailed;
    record.error = absl::StrCat("writing the labels: ", written.status().message());
  }
  Finish(record);
}

}  // namespace motiondb::server
