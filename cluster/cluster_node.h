// A server's part in a cluster: its registration under a lease, the shard map it follows and, on
// a router, its campaign to be the job coordinator, each kept up on a thread of its own while
// the server serves. etcd going away stops neither
// the server nor this: the node keeps the last map it saw and registers again when etcd is
// back. Thread-safe.
#ifndef MOTIONDB_CLUSTER_CLUSTER_NODE_H_
#define MOTIONDB_CLUSTER_CLUSTER_NODE_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/clip_router.h"
#include "cluster/cluster_options.h"
#include "cluster/etcd_client.h"
#include "cluster/leader_election.h"
#include "cluster/node_registration.h"
#include "cluster/shard_map.h"
#include "cluster/shard_map_watcher.h"

namespace motiondb::cluster {

class ClusterNode {
 public:
  // Registers the node (NodeRegistration::Start: ALREADY_EXISTS when its id is held by a live
  // node; INVALID_ARGUMENT for a bad name, id or role) and starts following the map.
  // `on_registered` runs whenever the registration is won or lost.
  static absl::StatusOr<std::unique_ptr<ClusterNode>> Start(
      const ClusterOptions& options, std::function<void(bool registered)> on_registered);
  // Deregisters (the lease revoked) and stops watching.
  ~ClusterNode();

  bool registered() const { return registration_->registered(); }
  // The newest map seen, nullptr before the first.
  std::shared_ptr<const ShardMap> map() const { return watcher_->map(); }
  // A shard node's check before it stores a write on clip `clip_id`: OK when the map as etcd holds
  // it now (ShardMapWatcher::CurrentMap, by `deadline`) gives the clip's shard to this node;
  // FAILED_PRECONDITION naming the shard, its node and the map's epoch when it gives it another
  // (the write was routed by an older map); UNAVAILABLE or NOT_FOUND as CurrentMap.
  absl::Status CheckClipOwner(int64_t clip_id, absl::Time deadline) const;
  // A router's route for the write of the clip named `name` (ClipRouter::Route);
  // FAILED_PRECONDITION on a shard node, which routes nothing.
  absl::StatusOr<ClipRoute> RouteClip(const std::string& name, absl::Time deadline) const;
  // ClipRouter::Settle on a router; FAILED_PRECONDITION on a shard node.
  absl::Status SettleClip(const std::string& name, const ClipRoute& route,
                          std::optional<int64_t> stored_clip_id) const;
  // ClipRouter::Locate, ReserveName and ReleaseName on a router; FAILED_PRECONDITION on a shard
  // node.
  absl::StatusOr<ClipRoute> LocateClip(int64_t clip_id, bool refresh) const;
  absl::Status ReserveClipName(const std::string& name, int64_t clip_id,
                               const ClipRouter::StillNamed& still_named) const;
  absl::Status ReleaseClipName(const std::string& name, int64_t clip_id) const;
  // ClipRouter::ShardNodes on a router; FAILED_PRECONDITION on a shard node.
  absl::StatusOr<std::vector<ShardNode>> ShardNodes(bool refresh) const;

 private:
  explicit ClusterNode(std::string node_id) : node_id_(std::move(node_id)) {}
  absl::Status CheckRouter() const;  // FAILED_PRECONDITION on a shard node

  const std::string node_id_;

  std::unique_ptr<EtcdClient> etcd_;
  std::unique_ptr<NodeRegistration> registration_;
  std::unique_ptr<ShardMapWatcher> watcher_;
  std::unique_ptr<LeaderElection> election_;  // a router's campaign for kJobsOffice
  std::unique_ptr<ClipRouter> router_;        // a router's
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLUSTER_NODE_H_
