// Jobs (storage/job_record.h) and the write that ends a propagation job.
#include <algorithm>
#include <cstdint>
#include <iterator>
#include <map>
#include <optional>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "absl/strings/strip.h"
#include "storage/database.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_checks.h"
#include "storage/internal/record_rows.h"
#include "util/status_macros.h"

namespace motiondb::storage {
namespace {

constexpr absl::string_view kJobPrefix = "job-";

constexpr absl::string_view kJobColumns =
    "job_number, kind, state, parameters, done, total, queries, queries_skipped, "
    "labels_written, error, created_unix_ms, started_unix_ms, finished_unix_ms";

absl::string_view StateText(JobState state) { return JobStateName(state); }

// The state JobStateName spells `text`; failed for any other text (the schema's CHECK allows
// none, but a row edited by hand should not give an out-of-range enum).
JobState StateOf(absl::string_view text) {
  for (const JobState state : {JobState::kQueued, JobState::kRunning, JobState::kSucceeded,
                               JobState::kFailed, JobState::kCancelled, JobState::kInterrupted}) {
    if (text == JobStateName(state)) return state;
  }
  return JobState::kFailed;
}

// The row number of "job-N"; nullopt for an id no job can have.
std::optional<int64_t> JobNumber(absl::string_view job_id) {
  int64_t number = 0;
  if (!absl::ConsumePrefix(&job_id, kJobPrefix) || !absl::SimpleAtoi(job_id, &number) ||
      number <= 0) {
    return std::nullopt;
  }
  return number;
}

absl::Status JobNotFound(absl::string_view job_id) {
  return absl::NotFoundError(absl::StrCat("job '", job_id.substr(0, 64), "' not found"));
}

JobRecord ReadJob(const SqliteStatement& row) {
  JobRecord job;
  job.job_id = absl::StrCat(kJobPrefix, row.ColumnInt64(0));
  job.kind = row.ColumnText(1);
  job.state = StateOf(row.ColumnText(2));
  job.parameters_json = row.ColumnText(3);
  job.done = row.ColumnInt64(4);
  job.total = row.ColumnInt64(5);
  job.queries = row.ColumnInt64(6);
  job.queries_skipped = row.ColumnInt64(7);
  job.labels_written = row.ColumnInt64(8);
  job.error = row.ColumnText(9);
  job.created_unix_ms = row.ColumnInt64(10);
  job.started_unix_ms = row.ColumnInt64(11);
  job.finished_unix_ms = row.ColumnInt64(12);
  return job;
}

absl::Status WriteJob(SqliteConnection& db, const JobRecord& job) {
  const std::optional<int64_t> number = JobNumber(job.job_id);
  if (!number) return JobNotFound(job.job_id);
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement update,
      db.Prepare("UPDATE jobs SET state = ?2, done = ?3, total = ?4, queries = ?5, "
                 "queries_skipped = ?6, labels_written = ?7, error = ?8, started_unix_ms = ?9, "
                 "finished_unix_ms = ?10 WHERE job_number = ?1"));
  MOTIONDB_RETURN_IF_ERROR(update.BindInt64(1, *number)
                               .BindText(2, StateText(job.state))
                               .BindInt64(3, job.done)
                               .BindInt64(4, job.total)
                               .BindInt64(5, job.queries)
                               .BindInt64(6, job.queries_skipped)
                               .BindInt64(7, job.labels_written)
                               .BindText(8, job.error)
                               .BindInt64(9, job.started_unix_ms)
                               .BindInt64(10, job.finished_unix_ms)
                               .Run());
  if (db.changes() == 0) return JobNotFound(job.job_id);
  return absl::OkStatus();
}

// What CheckLabel does not know about a label of a propagation's output: that it belongs there.
absl::Status CheckOutputLabel(const PropagationOutput& output, const LabelRecord& label,
                              size_t index) {
  MOTIONDB_RETURN_IF_ERROR(CheckLabel(label, index));
  const std::string item = absl::StrCat("labels[", index, "]");
  if (label.origin != LabelOrigin::kPropagated || label.job_id != output.job.job_id ||
      label.space_id != output.space_id) {
    return absl::InvalidArgumentError(absl::StrCat(item, ": not propagated by ", output.job.job_id,
                                                   " in space ", output.space_id));
  }
  if (std::find(output.descriptors.begin(), output.descriptors.end(), label.descriptor) ==
      output.descriptors.end()) {
    return absl::InvalidArgumentError(absl::StrCat(item, ".descriptor: '", label.descriptor,
                                                   "' is not one of the job's descriptors"));
  }
  return absl::OkStatus();
}

// Deletes the propagated labels of `output`'s descriptors in its space.
absl::Status DeleteOldOutput(SqliteConnection& db, const PropagationOutput& output) {
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement erase,
      db.Prepare("DELETE FROM labels WHERE origin = 'propagated' AND space_id = ?1 AND "
                 "descriptor = ?2"));
  for (const std::string& descriptor : output.descriptors) {
    erase.Reset();
    MOTIONDB_RETURN_IF_ERROR(erase.BindInt64(1, output.space_id).BindText(2, descriptor).Run());
  }
  return absl::OkStatus();
}

// Whether each of `keys` (distinct) has a row, by `sql` ("SELECT 1 FROM t WHERE key = ?").
absl::StatusOr<std::map<int64_t, bool>> RowsExist(SqliteConnection& db, absl::string_view sql,
                                                  std::map<int64_t, bool> keys) {
  for (auto& [key, exists] : keys) {
    MOTIONDB_ASSIGN_OR_RETURN(exists, Exists(db, sql, key));
  }
  return keys;
}

// Inserts the labels whose clip and source label still exist (either may have been deleted
// while the job ran); returns how many. Each clip and source is looked up once, not per label:
// the two lookups in every row's INSERT took 1.7 s of 2.9 for 59,116 labels.
absl::StatusOr<int64_t> InsertOutput(SqliteConnection& db, const PropagationOutput& output,
                                     int64_t now) {
  std::map<int64_t, bool> clips, sources;
  for (const LabelRecord& label : output.labels) {
    clips.emplace(label.clip_id, false);
    sources.emplace(label.source_label_id, false);
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      clips, RowsExist(db, "SELECT 1 FROM clips WHERE clip_id = ?", std::move(clips)));
  MOTIONDB_ASSIGN_OR_RETURN(
      sources, RowsExist(db, "SELECT 1 FROM labels WHERE label_id = ?", std::move(sources)));
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement insert,
      db.Prepare("INSERT INTO labels (clip_id, first_frame, last_frame, descriptor, value, "
                 "origin, source_label_id, space_id, score, job_id, created_unix_ms) "
                 "VALUES (?1, ?2, ?3, ?4, ?5, 'propagated', ?6, ?7, ?8, ?9, ?10)"));
  int64_t inserted = 0;
  for (const LabelRecord& label : output.labels) {
    if (!clips.at(label.clip_id) || !sources.at(label.source_label_id)) continue;
    insert.Reset();
    MOTIONDB_RETURN_IF_ERROR(insert.BindInt64(1, label.clip_id)
                                 .BindInt64(2, label.first_frame)
                                 .BindInt64(3, label.last_frame)
                                 .BindText(4, label.descriptor)
                                 .BindDouble(5, label.value)
                                 .BindInt64(6, label.source_label_id)
                                 .BindInt64(7, label.space_id)
                                 .BindDouble(8, label.score)
                                 .BindText(9, label.job_id)
                                 .BindInt64(10, now)
                                 .Run());
    ++inserted;
  }
  return inserted;
}

}  // namespace

absl::StatusOr<std::vector<std::string>> Database::ManualDescriptors() {
  std::vector<std::string> descriptors;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare("SELECT DISTINCT descriptor FROM labels WHERE origin = 'manual' "
                   "ORDER BY descriptor"));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      descriptors.push_back(query.ColumnText(0));
    }
  }));
  return descriptors;
}

absl::StatusOr<JobRecord> Database::CreateJob(const JobRecord& job, const WriteOptions& write) {
  if (job.kind != "propagation") {
    return absl::InvalidArgumentError(absl::StrCat("kind: unknown job kind '", job.kind, "'"));
  }
  if (IsFinal(job.state)) {
    return absl::InvalidArgumentError("state: a new job is queued or running");
  }
  JobRecord created = job;
  created.created_unix_ms = CreationTime(job.created_unix_ms);
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO jobs (kind, state, parameters, created_unix_ms) "
                   "VALUES (?1, ?2, ?3, ?4)"));
    MOTIONDB_RETURN_IF_ERROR(insert.BindText(1, created.kind)
                                 .BindText(2, StateText(created.state))
                                 .BindText(3, created.parameters_json)
                                 .BindInt64(4, created.created_unix_ms)
                                 .Run());
    created.job_id = absl::StrCat(kJobPrefix, db.last_insert_rowid());
    // The progress, counts and times the caller gave, as UpdateJob would write them.
    return WriteJob(db, created);
  }));
  return created;
}

absl::Status Database::UpdateJob(const JobRecord& job, const WriteOptions& write) {
  return impl_->Write(write, [&](SqliteConnection& db) { return WriteJob(db, job); });
}

absl::StatusOr<JobRecord> Database::GetJob(const std::string& job_id) {
  const std::optional<int64_t> number = JobNumber(job_id);
  if (!number) return JobNotFound(job_id);
  JobRecord job;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(absl::StrCat("SELECT ", kJobColumns, " FROM jobs WHERE job_number = ?")));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindInt64(1, *number).Step());
    if (!found) return JobNotFound(job_id);
    job = ReadJob(query);
    return absl::OkStatus();
  }));
  return job;
}

absl::StatusOr<std::map<JobState, int64_t>> Database::CountJobs() {
  std::map<JobState, int64_t> counts;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    // jobs_by_state serves the grouping: no scan of the parameters.
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              db.Prepare("SELECT state, count(*) FROM jobs GROUP BY state"));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      counts[StateOf(query.ColumnText(0))] += query.ColumnInt64(1);
    }
  }));
  return counts;
}

absl::StatusOr<JobPage> Database::ListJobs(const Page& page) {
  MOTIONDB_ASSIGN_OR_RETURN(const int page_size, CheckPageSize(page.page_size));
  int64_t before = INT64_MAX;
  if (!page.page_token.empty() && (!absl::SimpleAtoi(page.page_token, &before) || before <= 0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("malformed page_token '", page.page_token.substr(0, 40), "'"));
  }
  JobPage result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(absl::StrCat("SELECT ", kJobColumns,
                                " FROM jobs WHERE job_number < ? ORDER BY job_number DESC "
                                "LIMIT ?")));
    query.BindInt64(1, before).BindInt64(2, page_size + 1);
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) break;
      if (static_cast<int>(result.jobs.size()) == page_size) {
        // One row past the page: another page follows, after the page's last job.
        result.next_page_token =
            std::string(absl::string_view(result.jobs.back().job_id).substr(kJobPrefix.size()));
        break;
      }
      result.jobs.push_back(ReadJob(query));
    }
    return absl::OkStatus();
  }));
  return result;
}

absl::StatusOr<int64_t> Database::FinishPropagation(const PropagationOutput& output,
                                                    const WriteOptions& write) {
  for (size_t i = 0; i < output.labels.size(); ++i) {
    MOTIONDB_RETURN_IF_ERROR(CheckOutputLabel(output, output.labels[i], i));
  }
  int64_t inserted = 0;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    // The space may have been deleted while the job ran: its labels would then name no space.
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement space,
                              db.Prepare("SELECT 1 FROM spaces WHERE space_id = ?1"));
    MOTIONDB_ASSIGN_OR_RETURN(const bool space_exists, space.BindInt64(1, output.space_id).Step());
    if (!space_exists) {
      return absl::NotFoundError(
          absl::StrCat("space ", output.space_id, " was deleted while the job ran"));
    }
    MOTIONDB_RETURN_IF_ERROR(DeleteOldOutput(db, output));
    MOTIONDB_ASSIGN_OR_RETURN(inserted, InsertOutput(db, output, CreationTime(0)));
    JobRecord job = output.job;
    job.labels_written = inserted;
    return WriteJob(db, job);
  }));
  return inserted;
}

}  // namespace motiondb::storage
