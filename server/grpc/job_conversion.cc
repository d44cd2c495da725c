#include "server/grpc/job_conversion.h"

#include <utility>

#include "server/grpc/search_conversion.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {

absl::StatusOr<PropagationRequest> FromProto(const v1::StartPropagationRequest& request) {
  const v1::SearchRequest& search = request.search();
  // The fields a job sets per query, or that it does not do (the application refuses the
  // others: server/jobs/propagation.cc).
  const std::pair<bool, const char*> refused[] = {
      {!search.space().empty(), "search.space: give the space as space"},
      {search.query_case() != v1::SearchRequest::QUERY_NOT_SET,
       "search.query: the job's queries are its manual labels"},
      {search.tags_size() > 0, "search.tags: give the tags as tags"},
      {search.explain(), "search.explain: a propagation keeps no explanations"},
      {search.mirror(),
       "search.mirror: a propagation gives a label to ranges like its own, not to their mirror "
       "images"},
      {search.has_exclude_query(), "search.exclude_query: a query's own range is always excluded"},
      {search.has_characteristic_frame(), "search.characteristic_frame: each query finds its own"},
      {search.characteristic_frames_size() > 0,
       "search.characteristic_frames: each query finds its own"}};
  for (const auto& [set, message] : refused) {
    if (set) return absl::InvalidArgumentError(message);
  }
  PropagationRequest out;
  out.space = request.space();
  out.descriptors.assign(request.descriptor_names().begin(), request.descriptor_names().end());
  MOTIONDB_ASSIGN_OR_RETURN(out.search, Prefixed("search", FromProto(search)));
  out.search.params.tags.assign(request.tags().begin(), request.tags().end());
  if (!search.has_max_results()) out.search.params.max_results = kPropagationMaxResults;
  if (request.has_rival_share()) out.rival_share = request.rival_share();
  return out;
}

namespace {

v1::JobState ToProto(storage::JobState state) {
  switch (state) {
    case storage::JobState::kQueued:
      return v1::JOB_STATE_QUEUED;
    case storage::JobState::kRunning:
      return v1::JOB_STATE_RUNNING;
    case storage::JobState::kSucceeded:
      return v1::JOB_STATE_SUCCEEDED;
    case storage::JobState::kFailed:
      return v1::JOB_STATE_FAILED;
    case storage::JobState::kCancelled:
      return v1::JOB_STATE_CANCELLED;
    case storage::JobState::kInterrupted:
      return v1::JOB_STATE_INTERRUPTED;
  }
  return v1::JOB_STATE_UNSPECIFIED;
}

}  // namespace

void ToProto(const storage::JobRecord& record, v1::Job* job) {
  const PropagationTarget target = TargetOf(record);
  job->set_job_id(record.job_id);
  job->set_kind(record.kind);
  job->set_state(ToProto(record.state));
  job->set_space(target.space);
  for (const std::string& descriptor : target.descriptors) job->add_descriptor_names(descriptor);
  job->set_parameters(record.parameters_json);
  job->set_done(record.done);
  job->set_total(record.total);
  job->set_queries(record.queries);
  job->set_queries_skipped(record.queries_skipped);
  job->set_labels_written(record.labels_written);
  job->set_error(record.error);
  job->set_created_unix_ms(record.created_unix_ms);
  job->set_started_unix_ms(record.started_unix_ms);
  job->set_finished_unix_ms(record.finished_unix_ms);
}

void ToProto(const storage::JobPage& page, v1::ListJobsResponse* response) {
  for (const storage::JobRecord& record : page.jobs) ToProto(record, response->add_jobs());
  response->set_next_page_token(page.next_page_token);
}

}  // namespace motiondb::server
