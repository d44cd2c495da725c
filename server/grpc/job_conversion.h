// JobService's messages and the jobs' types (server/jobs/), both ways. A propagation's search
// is read as SearchService's is (server/grpc/search_conversion.h), less the fields a job sets
// for each of its queries.
#ifndef MOTIONDB_SERVER_GRPC_JOB_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_JOB_CONVERSION_H_

#include "absl/status/statusor.h"
#include "motiondb/v1/job_service.pb.h"
#include "server/jobs/propagation.h"
#include "storage/database.h"

namespace motiondb::server {

// INVALID_ARGUMENT naming search.FIELD for a search field the job sets itself.
absl::StatusOr<PropagationRequest> FromProto(const v1::StartPropagationRequest& request);

// The space and descriptors read from the job's parameters.
void ToProto(const storage::JobRecord& record, v1::Job* job);
void ToProto(const storage::JobPage& page, v1::ListJobsResponse* response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_JOB_CONVERSION_H_
