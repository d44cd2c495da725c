#include "server/grpc/shard_service.h"

#include <chrono>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "server/grpc/clip_conversion.h"
#include "server/grpc/internal/upload_ingest.h"
#include "server/grpc/serve.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// The call's deadline; a call without one is given this long for the map's read.
constexpr absl::Duration kMapReadWithoutDeadline = absl::Seconds(10);

absl::Time MapReadDeadline(const grpc::ServerContext& context) {
  const auto deadline = context.deadline();
  if (deadline == std::chrono::system_clock::time_point::max()) {
    return absl::Now() + kMapReadWithoutDeadline;
  }
  return absl::FromChrono(deadline);
}

}  // namespace

grpc::Status ShardServiceImpl::StoreTake(grpc::ServerContext* context,
                                         const shard::v1::StoreTakeRequest* request,
                                         v1::IngestClipResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(IngestRequest ingest, FromProto(request->ingest()));
    if (request->clip_id() < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("clip_id: ", request->clip_id(), "; a routed take needs a positive id"));
    }
    ingest.routed = IngestRequest::Routed{.take = request->take(), .clip_id = request->clip_id()};
    MOTIONDB_RETURN_IF_ERROR(check_owner_(request->clip_id(), MapReadDeadline(*context)));
    return IngestUploadedFile({catalog_, limits_, budget_, metrics_}, ingest,
                              request->ingest().bvh(), should_stop, response);
  });
}

}  // namespace motiondb::server
