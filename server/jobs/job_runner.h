// Background jobs (SPEC §7): propagation jobs queued and run one at a time by one worker
// thread (a job's searches spread over JobRunnerOptions::threads), their rows kept in the
// database (storage/job_record.h) and their live progress here.
//
// The worker runs at a lower CPU priority than the threads serving calls: it raises its own
// nice value by kWorkerNiceIncrement (Linux keeps a nice value per thread, and the threads it
// and a search start inherit it), so that while a job runs, interactive searches get the cores
// first and the job takes what is left. Cancellation and shutdown are checked between queries and
// inside each search. A job's output and its final row are written in one transaction at its end
// (storage::Database::FinishPropagation): a job cut off by a stop or a crash leaves nothing
// half-written and becomes `interrupted` (at Stop(), or at the next open after a crash).
//
// A descriptor is propagated by one job at a time: a job whose descriptors overlap those of a
// queued or running one is refused (FAILED_PRECONDITION naming that job) rather than queued
// behind it, since both would replace the same output.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_JOBS_JOB_RUNNER_H_
#define MOTIONDB_SERVER_JOBS_JOB_RUNNER_H_

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "server/index_registry.h"
#include "server/jobs/propagation.h"
#include "server/listing.h"
#include "server/search_runner.h"
#include "storage/database.h"

namespace motiondb::server {

inline constexpr int kMaxQueuedJobs = 16;
inline constexpr int kWorkerNiceIncrement = 10;
// How many ended jobs are kept in memory: reads of a job that ended recently are answered from
// there, so that its end is seen even when its final row could not be written (a full disk).
inline constexpr size_t kRecentlyEndedJobs = 64;

// Whether two views of a job show the same state, progress and counts (a watcher's "nothing
// new").
bool SameProgress(const storage::JobRecord& a, const storage::JobRecord& b);

struct JobRunnerOptions {
  // Threads a job's searches run on, all at the worker's lowered priority (0: one per core). One
  // thread leaves a core idle while the machine has nothing else to do; interactive searches
  // take their share of the cores first whatever the number.
  int threads = 0;
  // >= 0 (tests only): a running job with labels left waits after that many until it is
  // cancelled or the runner stops, so that a test sees it running whatever the machine's speed.
  int test_pause_after = -1;
};

class JobRunner {
 public:
  JobRunner(storage::Database& database, const IndexRegistry& registry, const SearchRunner& runner,
            const JobRunnerOptions& options = {});
  JobRunner(const JobRunner&) = delete;
  JobRunner& operator=(const JobRunner&) = delete;
  ~JobRunner();  // Stop()

  // Queues a propagation job and returns it (queued). ResolvePropagation's errors;
  // FAILED_PRECONDITION when a queued or running job propagates one of the descriptors;
  // RESOURCE_EXHAUSTED past kMaxQueuedJobs waiting jobs; UNAVAILABLE once stopping.
  absl::StatusOr<storage::JobRecord> StartPropagation(PropagationRequest request);
  // The job as it is now (a live job's progress from memory, fresher than its row). NOT_FOUND.
  absl::StatusOr<storage::JobRecord> Get(const std::string& job_id) const;
  // Newest first, live jobs as Get gives them.
  absl::StatusOr<storage::JobPage> List(const PageRequest& page) const;
  // Cancels a queued job at once (returned cancelled) and asks a running one to stop at its next
  // check, without waiting (returned as it is, running: watch it to see its end, cancelled, or
  // its own end when it finished first). NOT_FOUND; FAILED_PRECONDITION naming the state for a
  // job that had ended already.
  absl::StatusOr<storage::JobRecord> Cancel(const std::string& job_id);
  // Whether the job is queued or running here (false once it ended, whatever its row says).
  bool IsLive(const std::string& job_id) const;
  // The job once it differs from `seen` (progress, counts or state), or as it is after
  // `max_wait`. NOT_FOUND.
  absl::StatusOr<storage::JobRecord> WaitForChange(const std::string& job_id,
                                                   const storage::JobRecord& seen,
                                                   std::chrono::milliseconds max_wait) const;
  // Ends the running job and the queued ones as interrupted, and joins the worker; new jobs are
  // refused from then on. Idempotent.
  void Stop();
  // Stop() without the join: the running job is asked to stop and ends on its own. Stop()
  // afterwards joins.
  void RequestStop();

 private:
  struct Live {
    storage::JobRecord record;
    PropagationRequest request;
  };

  void Work();
  // Runs the job `job_id` (its Live entry present) to its end and records the end.
  void Run(const std::string& job_id);
  // The first live job sharing a descriptor with `descriptors`, or null.
  const Live* Conflict(const std::vector<std::string>& descriptors) const;
  // Records `record` (its end) in memory and in the database, and drops the live entry.
  void Finish(const storage::JobRecord& record);
  // Moves the live entry of `record` to ended_ as `record`. Under mutex_.
  void EndLocked(const storage::JobRecord& record);
  // The job from live_ or ended_, or null. Under mutex_.
  const storage::JobRecord* FindLocked(const std::string& job_id) const;

  storage::Database& database_;
  const IndexRegistry& registry_;
  const SearchRunner& runner_;
  const JobRunnerOptions options_;
  mutable std::mutex mutex_;
  // Notified on every change of a live job and when stopping.
  mutable std::condition_variable changed_;
  std::map<std::string, Live> live_;      // queued and running jobs
  std::deque<std::string> queue_;         // the queued ones, first to run first
  std::deque<storage::JobRecord> ended_;  // the last kRecentlyEndedJobs ended, oldest first
  std::string running_id_;                // the running job; empty when none runs
  bool stopping_ = false;
  // The running job's should_stop: set by Cancel (for running_id_ only) and Stop; cleared as a
  // job starts.
  std::atomic<bool> stop_running_{false};
  // The spaces' score scales, kept between jobs (only the worker uses it).
  ScoreScales scales_;
  std::thread worker_;  // last: started once the rest exists
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_JOBS_JOB_RUNNER_H_
