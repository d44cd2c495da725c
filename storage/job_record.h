// Jobs (SPEC §7): background work kept as rows, so that its state, progress and outcome outlive
// the call that started it and the process that ran it. What storage::Database's job operations
// take and return.
#ifndef MOTIONDB_STORAGE_JOB_RECORD_H_
#define MOTIONDB_STORAGE_JOB_RECORD_H_

#include <cstdint>
#include <string>
#include <vector>

#include "storage/label_record.h"

namespace motiondb::storage {

// queued -> running -> succeeded | failed | cancelled; queued or running -> interrupted when the
// process that ran the job ended first (a shutdown, a crash, kill -9).
enum class JobState { kQueued, kRunning, kSucceeded, kFailed, kCancelled, kInterrupted };

// "queued", "running", "succeeded", "failed", "cancelled", "interrupted": the state as rows,
// logs, errors and the CLI spell it.
inline const char* JobStateName(JobState state) {
  switch (state) {
    case JobState::kQueued:
      return "queued";
    case JobState::kRunning:
      return "running";
    case JobState::kSucceeded:
      return "succeeded";
    case JobState::kFailed:
      return "failed";
    case JobState::kCancelled:
      return "cancelled";
    case JobState::kInterrupted:
      return "interrupted";
  }
  return "unknown";
}

// True for the states a job never leaves.
inline bool IsFinal(JobState state) {
  return state != JobState::kQueued && state != JobState::kRunning;
}

struct JobRecord {
  // "job-N", N the row's number: assigned by CreateJob, never reused.
  std::string job_id{};
  std::string kind = "propagation";
  JobState state = JobState::kQueued;
  std::string parameters_json = "{}";  // what the job was asked, as its starter records it
  int64_t done = 0, total = 0;         // progress, in the job's own units (propagation: queries)
  int64_t queries = 0;                 // searches run
  int64_t queries_skipped = 0;         // labels whose range could not be a query
  int64_t labels_written = 0;
  std::string error{};           // why it failed or was interrupted; empty otherwise
  int64_t created_unix_ms = 0;   // 0 on create: the time of the insert
  int64_t started_unix_ms = 0;   // 0 until it runs
  int64_t finished_unix_ms = 0;  // 0 until it ends
};

struct JobPage {
  std::vector<JobRecord> jobs;
  std::string next_page_token;  // empty on the last page
};

// What a propagation job writes when it succeeds: `labels` (propagated, of `descriptors`, found
// in space `space_id`) replacing the propagated labels of those descriptors from that space,
// together with the job's final row `job`.
struct PropagationOutput {
  JobRecord job;
  int64_t space_id = 0;
  std::vector<std::string> descriptors;
  std::vector<LabelRecord> labels;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_JOB_RECORD_H_
