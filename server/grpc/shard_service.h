// motiondb.shard.v1.ShardService, served by a cluster's shard node beside motiondb.v1: what its
// router asks of it. The node stores a write only when the shard map gives it the write's shard
// (`check_owner`, ServerOptions::check_shard_owner), so that a router routing by an older map
// cannot store a clip on a node that no longer holds its shard.
#ifndef MOTIONDB_SERVER_GRPC_SHARD_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_SHARD_SERVICE_H_

#include <cstdint>
#include <functional>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "motiondb/shard/v1/shard_service.grpc.pb.h"
#include "server/catalog.h"
#include "server/grpc/call_gate.h"
#include "server/metrics/server_metrics.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

// Whether the shard map, read by `deadline`, gives clip `clip_id`'s shard to this node: OK, or
// FAILED_PRECONDITION naming its node (UNAVAILABLE when the map cannot be read).
using ShardOwnerCheck = std::function<absl::Status(int64_t clip_id, absl::Time deadline)>;

class ShardServiceImpl final : public shard::v1::ShardService::Service {
 public:
  ShardServiceImpl(Catalog& catalog, const UploadLimits& limits, UploadBudget& budget,
                   ServerMetrics& metrics, CallGate& gate, ShardOwnerCheck check_owner)
      : catalog_(catalog),
        limits_(limits),
        budget_(budget),
        metrics_(metrics),
        gate_(gate),
        check_owner_(std::move(check_owner)) {}

  grpc::Status StoreTake(grpc::ServerContext* context, const shard::v1::StoreTakeRequest* request,
                         v1::IngestClipResponse* response) override;
  grpc::Status UpdateClip(grpc::ServerContext* context, const v1::UpdateClipRequest* request,
                          v1::Clip* response) override;

 private:
  Catalog& catalog_;
  UploadLimits limits_;
  UploadBudget& budget_;
  ServerMetrics& metrics_;
  CallGate& gate_;
  ShardOwnerCheck check_owner_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SHARD_SERVICE_H_
