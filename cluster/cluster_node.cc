#include "cluster/cluster_node.h"

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"
#include "util/status_macros.h"

namespace motiondb::cluster {

absl::StatusOr<std::unique_ptr<ClusterNode>> ClusterNode::Start(
    const ClusterOptions& options, std::function<void(bool registered)> on_registered) {
  MOTIONDB_RETURN_IF_ERROR(CheckClusterName(options.cluster, "--cluster-name"));
  MOTIONDB_RETURN_IF_ERROR(CheckClusterName(options.node.node_id, "--node-id"));
  if (!IsNodeRole(options.node.role)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--role '", options.node.role, "': want shard or router"));
  }
  std::unique_ptr<ClusterNode> node(new ClusterNode(options.node.node_id));
  MOTIONDB_ASSIGN_OR_RETURN(node->etcd_, EtcdClient::Create(options.etcd));
  MOTIONDB_ASSIGN_OR_RETURN(node->registration_, NodeRegistration::Start(*node->etcd_, options,
                                                                         std::move(on_registered)));
  NodeRegistration* registration = node->registration_.get();
  const std::string node_id = options.node.node_id;
  node->watcher_ = std::make_unique<ShardMapWatcher>(
      *node->etcd_, options, [registration, node_id](const ShardMap& map) {
        registration->SetShards(map.ShardsOf(node_id));
      });
  if (options.node.role == "router") {
    if (options.max_clip_name_bytes == 0) {
      return absl::InvalidArgumentError("a router needs the longest clip name's length");
    }
    node->router_ = std::make_unique<ClipRouter>(*node->etcd_, *node->watcher_, options.cluster,
                                                 options.max_clip_name_bytes);
    const std::function<void(const std::string&)> log = options.log;
    const std::string cluster = options.cluster;
    MOTIONDB_ASSIGN_OR_RETURN(
        node->election_, LeaderElection::Start(
                             *node->etcd_, options.cluster, kJobsOffice, node_id, options.lease_ttl,
                             [log, cluster](bool leading) {
                               if (!log) return;
                               log(absl::StrCat("cluster '", cluster, "': ",
                                                leading ? "this node is" : "this node is no longer",
                                                " the job coordinator"));
                             }));
  }
  return node;
}

absl::Status ClusterNode::CheckClipOwner(int64_t clip_id, absl::Time deadline) const {
  MOTIONDB_ASSIGN_OR_RETURN(const ShardMap map, watcher_->CurrentMap(deadline));
  const int shard = ShardOfClip(clip_id, map.shard_count());
  const std::string& owner = map.owners[shard];
  if (owner == node_id_) return absl::OkStatus();
  return absl::FailedPreconditionError(absl::StrCat(
      "clip ", clip_id, "'s shard ", shard, " is node '", owner, "''s in the map of epoch ",
      map.epoch, ", not this node's ('", node_id_, "'): route the write by the newest map"));
}

absl::StatusOr<ClipRoute> ClusterNode::RouteClip(const std::string& name,
                                                 absl::Time deadline) const {
  MOTIONDB_RETURN_IF_ERROR(CheckRouter());
  return router_->Route(name, deadline);
}

absl::Status ClusterNode::SettleClip(const std::string& name, const ClipRoute& route,
                                     std::optional<int64_t> stored_clip_id) const {
  MOTIONDB_RETURN_IF_ERROR(CheckRouter());
  return router_->Settle(name, route, stored_clip_id);
}

absl::StatusOr<ClipRoute> ClusterNode::LocateClip(int64_t clip_id, bool refresh) const {
  MOTIONDB_RETURN_IF_ERROR(CheckRouter());
  return router_->Locate(clip_id, refresh);
}

absl::Status ClusterNode::ReserveClipName(const std::string& name, int64_t clip_id,
                                          const ClipRouter::StillNamed& still_named) const {
  MOTIONDB_RETURN_IF_ERROR(CheckRouter());
  return router_->ReserveName(name, clip_id, still_named);
}

absl::Status ClusterNode::ReleaseClipName(const std::string& name, int64_t clip_id) const {
  MOTIONDB_RETURN_IF_ERROR(CheckRouter());
  return router_->ReleaseName(name, clip_id);
}

absl::StatusOr<std::vector<ShardNode>> ClusterNode::ShardNodes(bool refresh) const {
  MOTIONDB_RETURN_IF_ERROR(CheckRouter());
  return router_->ShardNodes(refresh);
}

absl::Status ClusterNode::CheckRouter() const {
  if (router_ != nullptr) return absl::OkStatus();
  return absl::FailedPreconditionError(
      absl::StrCat("node '", node_id_, "' is a shard node; a router routes writes"));
}

ClusterNode::~ClusterNode() {
  router_.reset();    // it reads the watcher
  election_.reset();  // resigns, so that another router takes the office at once
  watcher_.reset();   // it writes to the registration
  registration_.reset();
}

}  // namespace motiondb::cluster
