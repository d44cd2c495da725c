#include "server/grpc/job_service.h"

#include <chrono>

#include "absl/strings/str_cat.h"

#include "server/grpc/job_conversion.h"
#include "server/grpc/serve.h"
#include "server/grpc/status_conversion.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// How long a watch waits for a change before it looks whether its call is still there: gRPC
// does not wake a handler when its client goes.
constexpr std::chrono::milliseconds kWatchPoll{200};

}  // namespace

grpc::Status JobServiceImpl::StartPropagation(grpc::ServerContext* context,
                                              const v1::StartPropagationRequest* request,
                                              v1::Job* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(PropagationRequest propagation, FromProto(*request));
    MOTIONDB_ASSIGN_OR_RETURN(const storage::JobRecord job,
                              jobs_.StartPropagation(std::move(propagation)));
    ToProto(job, response);
    return absl::OkStatus();
  });
}

grpc::Status JobServiceImpl::GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request,
                                    v1::Job* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::JobRecord job, jobs_.Get(request->job_id()));
    ToProto(job, response);
    return absl::OkStatus();
  });
}

grpc::Status JobServiceImpl::ListJobs(grpc::ServerContext* context,
                                      const v1::ListJobsRequest* request,
                                      v1::ListJobsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::JobPage page,
                              jobs_.List({request->page_size(), request->page_token()}));
    ToProto(page, response);
    return absl::OkStatus();
  });
}

grpc::Status JobServiceImpl::CancelJob(grpc::ServerContext* context,
                                       const v1::CancelJobRequest* request, v1::Job* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::JobRecord job, jobs_.Cancel(request->job_id()));
    ToProto(job, response);
    return absl::OkStatus();
  });
}

grpc::Status JobServiceImpl::WatchJob(grpc::ServerContext* context,
                                      const v1::WatchJobRequest* request,
                                      grpc::ServerWriter<v1::Job>* writer) {
  if (watches_.fetch_add(1) >= kMaxJobWatches) {
    watches_.fetch_sub(1);
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        absl::StrCat(kMaxJobWatches,
                                     " job watches are open, the most the server keeps; watch "
                                     "again later or poll GetJob"));
  }
  struct Release {
    std::atomic<int>& count;
    ~Release() { count.fetch_sub(1); }
  } release{watches_};
  absl::StatusOr<storage::JobRecord> job;
  const grpc::Status admitted = Serve(gate_, context, [&](const ShouldStop&) {
    job = jobs_.Get(request->job_id());
    return job.status();
  });
  if (!admitted.ok()) return admitted;
  v1::Job message;
  ToProto(*job, &message);
  if (!writer->Write(message)) return grpc::Status(grpc::StatusCode::CANCELLED, "the client left");
  while (!storage::IsFinal(job->state)) {
    if (context->IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "the watch was cancelled");
    }
    const storage::JobRecord seen = *job;
    job = jobs_.WaitForChange(request->job_id(), seen, kWatchPoll);
    if (!job.ok()) return ToGrpcStatus(job.status());
    if (SameProgress(*job, seen)) {
      // The wait timed out, or the job ended here while its row could not say so (a failed
      // write leaves it queued or running there): not live means ended.
      if (jobs_.IsLive(request->job_id())) continue;
      job = jobs_.Get(request->job_id());  // its end, if it came after the wait
      if (!job.ok() || SameProgress(*job, seen)) return grpc::Status::OK;
      message.Clear();
      ToProto(*job, &message);
      writer->Write(message);
      return grpc::Status::OK;
    }
    message.Clear();
    ToProto(*job, &message);
    if (!writer->Write(message)) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "the client left");
    }
  }
  return grpc::Status::OK;
}

}  // namespace motiondb::server
