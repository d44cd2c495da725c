// motiondb.v1.JobService: start, look at, list, cancel and watch background jobs
// (server/jobs/job_runner.h runs them).
#ifndef MOTIONDB_SERVER_GRPC_JOB_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_JOB_SERVICE_H_

#include <atomic>

#include "motiondb/v1/job_service.grpc.pb.h"
#include "server/grpc/call_gate.h"
#include "server/jobs/job_runner.h"

namespace motiondb::server {

// The most WatchJob streams open at once: each holds one of gRPC's threads while it waits, so
// that many watches could otherwise leave no thread for the other calls.
inline constexpr int kMaxJobWatches = 64;

class JobServiceImpl final : public v1::JobService::Service {
 public:
  JobServiceImpl(JobRunner& jobs, CallGate& gate) : jobs_(jobs), gate_(gate) {}

  grpc::Status StartPropagation(grpc::ServerContext* context,
                                const v1::StartPropagationRequest* request,
                                v1::Job* response) override;
  grpc::Status GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request,
                      v1::Job* response) override;
  grpc::Status ListJobs(grpc::ServerContext* context, const v1::ListJobsRequest* request,
                        v1::ListJobsResponse* response) override;
  grpc::Status CancelJob(grpc::ServerContext* context, const v1::CancelJobRequest* request,
                         v1::Job* response) override;
  // Admitted through the call gate like every call, but waits for changes outside it: a watch
  // may last as long as the job, and holding a --threads slot that long would starve the calls
  // that do work. RESOURCE_EXHAUSTED past kMaxJobWatches open watches.
  grpc::Status WatchJob(grpc::ServerContext* context, const v1::WatchJobRequest* request,
                        grpc::ServerWriter<v1::Job>* writer) override;

 private:
  JobRunner& jobs_;
  CallGate& gate_;
  std::atomic<int> watches_{0};
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_JOB_SERVICE_H_
