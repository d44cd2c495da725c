// motiondb.v1.ClipService on a cluster's router: an ingest's takes each stored on the shard node
// its clip id belongs to (motiondb.shard.v1.ShardService.StoreTake), the ids and the names
// reserved cluster-wide first and settled after (`routing`, cluster::ClipRouter); a call on one
// clip (get, export, poses, update, delete) passed to its shard's node; a listing asked of every
// node holding shards and merged (server/listing.h). The rest of the service is not routed yet:
// UNIMPLEMENTED (ARCHITECTURE.md, "The cluster").
#ifndef MOTIONDB_SERVER_GRPC_ROUTED_CLIP_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_ROUTED_CLIP_SERVICE_H_

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "absl/strings/string_view.h"

#include "motiondb/shard/v1/shard_service.grpc.pb.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "server/answer_limit.h"
#include "server/grpc/call_gate.h"
#include "server/grpc/server_options.h"
#include "server/grpc/stream_watchdog.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

class RoutedClipServiceImpl final : public v1::ClipService::Service {
 public:
  // `budget` and `watchdog` bound the ingests in progress, as ClipServiceImpl's; a node's
  // answer may be as large as `answers` allows (the nodes' --max-answer-mb), and what is sent to
  // a node at most `max_message_bytes` (their --max-message-mb). Every call to a node presents
  // `cluster_token` (ServerOptions::cluster_token), none when it is empty.
  RoutedClipServiceImpl(const UploadLimits& limits, UploadBudget& budget, StreamWatchdog& watchdog,
                        CallGate& gate, const AnswerLimit& answers, int64_t max_message_bytes,
                        std::shared_ptr<ClipRouting> routing, std::string cluster_token)
      : limits_(limits),
        budget_(budget),
        watchdog_(watchdog),
        gate_(gate),
        answers_(answers),
        max_message_bytes_(max_message_bytes),
        routing_(std::move(routing)),
        cluster_token_(std::move(cluster_token)) {}

  grpc::Status IngestClip(grpc::ServerContext* context, const v1::IngestClipRequest* request,
                          v1::IngestClipResponse* response) override;
  grpc::Status IngestClipStream(grpc::ServerContext* context,
                                grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
                                v1::IngestClipResponse* response) override;
  grpc::Status GetClip(grpc::ServerContext* context, const v1::GetClipRequest* request,
                       v1::Clip* response) override;
  grpc::Status ExportClip(grpc::ServerContext* context, const v1::ExportClipRequest* request,
                          v1::ExportClipResponse* response) override;
  grpc::Status ExportClipStream(grpc::ServerContext* context, const v1::ExportClipRequest* request,
                                grpc::ServerWriter<v1::ExportClipResponse>* writer) override;
  grpc::Status GetClipPoses(grpc::ServerContext* context, const v1::GetClipPosesRequest* request,
                            v1::ClipPoses* response) override;
  grpc::Status ListClips(grpc::ServerContext* context, const v1::ListClipsRequest* request,
                         v1::ListClipsResponse* response) override;
  // A rename reserves the new name in the cluster first (ALREADY_EXISTS when another clip holds
  // it and is still named so), has the shard rename the clip (ShardService.UpdateClip), then frees
  // the old name.
  grpc::Status UpdateClip(grpc::ServerContext* context, const v1::UpdateClipRequest* request,
                          v1::Clip* response) override;
  // Frees the clip's name in the cluster once its shard has deleted it.
  grpc::Status DeleteClip(grpc::ServerContext* context, const v1::DeleteClipRequest* request,
                          v1::DeleteClipResponse* response) override;

 private:
  // A shard node's services, over one channel.
  struct NodeStubs {
    std::unique_ptr<shard::v1::ShardService::Stub> shard;
    std::unique_ptr<v1::ClipService::Stub> clips;
  };
  // A call to the node holding clip `clip_id`, in `context`'s name (its deadline, cancellation
  // and the cluster's token).
  struct NodeCall {
    cluster::ClipRoute route;
    v1::ClipService::Stub* clips = nullptr;
    std::unique_ptr<grpc::ClientContext> context;
  };
  // A call to a node in the name of the call `from`: its deadline and cancellation, and the
  // cluster's token.
  std::unique_ptr<grpc::ClientContext> NodeContext(const grpc::ServerContext& from) const;
  absl::StatusOr<NodeCall> CallClipNode(const grpc::ServerContext& context, int64_t clip_id);
  // The clip as its node holds it (its name, before a rename or a delete), through `call`.
  absl::StatusOr<v1::Clip> ClipOnNode(NodeCall& call, int64_t clip_id);
  // Frees `name` in the cluster if clip `clip_id` holds it, once the clip was `done` (deleted,
  // renamed); a failed release is logged.
  void FreeName(const std::string& name, int64_t clip_id, absl::string_view done);
  // What a node's failure tells the caller; the clip's node is looked up afresh next time when
  // it did not answer.
  absl::Status NodeFailed(const grpc::Status& status, const cluster::ClipRoute& route);
  absl::Status NodeFailed(const grpc::Status& status, const std::string& node_id,
                          const std::string& address, const std::string& holding);
  // A unary call on one clip, passed to its node.
  template <typename Request, typename Response>
  grpc::Status Pass(grpc::ServerContext* context, int64_t clip_id, const Request& request,
                    Response* response,
                    grpc::Status (v1::ClipService::Stub::*method)(grpc::ClientContext*,
                                                                  const Request&, Response*));

  // Every take of `file` (read from `store`'s ingest, whose clip name is `name`) stored on its
  // shard: `store` is sent for each, with the take's index and id.
  absl::Status StoreTakes(grpc::ServerContext& context, shard::v1::StoreTakeRequest& store,
                          const std::string& name, const UploadedFile& file,
                          v1::IngestClipResponse* response);
  // Take `take` of the file stored under its route: the shard's answer, the name settled.
  absl::Status StoreTake(grpc::ServerContext& context, shard::v1::StoreTakeRequest& store,
                         size_t take, const std::string& take_name,
                         v1::IngestClipResponse* response);
  // One channel a shard node, kept for the router's life.
  NodeStubs& NodeAt(const std::string& address);

  UploadLimits limits_;
  UploadBudget& budget_;
  StreamWatchdog& watchdog_;
  CallGate& gate_;
  const AnswerLimit answers_;
  const int64_t max_message_bytes_;
  std::shared_ptr<ClipRouting> routing_;
  const std::string cluster_token_;
  std::mutex mutex_;
  std::map<std::string, NodeStubs> nodes_;  // guarded by mutex_; by address
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_ROUTED_CLIP_SERVICE_H_
