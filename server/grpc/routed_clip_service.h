// motiondb.v1.ClipService on a cluster's router: an ingest's takes each stored on the shard node
// its clip id belongs to (motiondb.shard.v1.ShardService.StoreTake), the ids and the names
// reserved cluster-wide first and settled after (`routing`, cluster::ClipRouter). The rest of the
// service is not routed yet: UNIMPLEMENTED (ARCHITECTURE.md, "The cluster").
#ifndef MOTIONDB_SERVER_GRPC_ROUTED_CLIP_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_ROUTED_CLIP_SERVICE_H_

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "motiondb/shard/v1/shard_service.grpc.pb.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "server/grpc/call_gate.h"
#include "server/grpc/server_options.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

class RoutedClipServiceImpl final : public v1::ClipService::Service {
 public:
  RoutedClipServiceImpl(const UploadLimits& limits, UploadBudget& budget, CallGate& gate,
                        std::shared_ptr<ClipRouting> routing)
      : limits_(limits), budget_(budget), gate_(gate), routing_(std::move(routing)) {}

  grpc::Status IngestClip(grpc::ServerContext* context, const v1::IngestClipRequest* request,
                          v1::IngestClipResponse* response) override;

 private:
  // Take `take` of the file stored under its route: the shard's answer, the name settled.
  absl::Status StoreTake(grpc::ServerContext& context, const v1::IngestClipRequest& request,
                         size_t take, const std::string& take_name,
                         v1::IngestClipResponse* response);
  // One channel a shard node, kept for the router's life.
  shard::v1::ShardService::Stub& ShardAt(const std::string& address);

  UploadLimits limits_;
  UploadBudget& budget_;
  CallGate& gate_;
  std::shared_ptr<ClipRouting> routing_;
  std::mutex mutex_;
  std::map<std::string, std::unique_ptr<shard::v1::ShardService::Stub>> shards_;  // by address
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_ROUTED_CLIP_SERVICE_H_
