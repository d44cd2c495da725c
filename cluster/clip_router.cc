#include "cluster/clip_router.h"

#include <memory>
#include <optional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "cluster/node_info.h"
#include "cluster/shard_map.h"
#include "util/status_macros.h"

namespace motiondb::cluster {

ClipRouter::ClipRouter(const EtcdClient& etcd, const ShardMapWatcher& watcher,
                       const std::string& cluster, size_t max_name_bytes)
    : etcd_(etcd),
      watcher_(watcher),
      cluster_(cluster),
      ids_(etcd, cluster),
      names_(etcd, cluster, max_name_bytes) {}

absl::StatusOr<int64_t> ClipRouter::NextIdOnShard(int shard, int shard_count) {
  // About shard_count draws; a bound far beyond, so that a broken hash cannot spin for ever.
  const int64_t most = int64_t{shard_count} * 1000;
  for (int64_t draw = 0; draw < most; ++draw) {
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t id, ids_.Next());
    if (ShardOfClip(id, shard_count) == shard) return id;
  }
  return absl::InternalError(absl::StrCat("no id of shard ", shard, " in ", most, " ids"));
}

absl::StatusOr<ClipRoute> ClipRouter::Route(const std::string& name, absl::Time deadline) {
  MOTIONDB_ASSIGN_OR_RETURN(const ShardMap map, watcher_.CurrentMap(deadline));
  ClipRoute route;
  MOTIONDB_ASSIGN_OR_RETURN(std::optional<int64_t> held, names_.Lookup(name));
  if (!held) {
    MOTIONDB_ASSIGN_OR_RETURN(route.clip_id, ids_.Next());
    const absl::Status reserved = names_.Reserve(name, route.clip_id);
    if (!reserved.ok()) {
      if (!absl::IsAlreadyExists(reserved)) return reserved;
      // Reserved by another router since the lookup: that clip's name, as though held before.
      MOTIONDB_ASSIGN_OR_RETURN(held, names_.Lookup(name));
      if (!held) {
        return absl::AbortedError(
            absl::StrCat("clip name '", name, "' was reserved and freed meanwhile; try again"));
      }
    }
  }
  if (held) {
    route.held_by = *held;
    MOTIONDB_ASSIGN_OR_RETURN(
        route.clip_id, NextIdOnShard(ShardOfClip(*held, map.shard_count()), map.shard_count()));
  }
  // A write is routed to a node live now, not to an address remembered.
  MOTIONDB_RETURN_IF_ERROR(RouteTo(map, /*refresh=*/true, route));
  return route;
}

absl::Status ClipRouter::RouteTo(const ShardMap& map, bool refresh, ClipRoute& route) {
  route.shard = ShardOfClip(route.clip_id, map.shard_count());
  route.epoch = map.epoch;
  route.node_id = map.owners[route.shard];
  MOTIONDB_ASSIGN_OR_RETURN(route.address,
                            AddressOf(route.node_id, route.shard, map.epoch, refresh));
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<const ShardMap>> ClipRouter::LastMap() const {
  std::shared_ptr<const ShardMap> map = watcher_.map();
  if (map != nullptr) return map;
  return absl::UnavailableError(
      "the cluster's shard map has not been read yet (is the cluster initialised, and etcd "
      "reachable?)");
}

absl::StatusOr<std::string> ClipRouter::AddressOf(const std::string& node_id, int shard,
                                                  int64_t epoch, bool refresh) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto known = addresses_.find(node_id);
    if (!refresh && known != addresses_.end()) return known->second;
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<NodeInfo> nodes, ListNodes(etcd_, cluster_));
  std::lock_guard<std::mutex> lock(mutex_);
  addresses_.clear();
  for (const NodeInfo& node : nodes) addresses_[node.node_id] = node.address;
  const auto live = addresses_.find(node_id);
  if (live != addresses_.end()) return live->second;
  return absl::UnavailableError(
      absl::StrCat("shard ", shard, "'s node '", node_id, "' is not live (map epoch ", epoch, ")"));
}

absl::StatusOr<ClipRoute> ClipRouter::Locate(int64_t clip_id, bool refresh) {
  if (clip_id < 1) {
    return absl::InvalidArgumentError(absl::StrCat("clip_id: ", clip_id, "; ids are positive"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const ShardMap> map, LastMap());
  ClipRoute route;
  route.clip_id = clip_id;
  MOTIONDB_RETURN_IF_ERROR(RouteTo(*map, refresh, route));
  return route;
}

absl::StatusOr<std::vector<ShardNode>> ClipRouter::ShardNodes(bool refresh) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const ShardMap> map, LastMap());
  std::vector<ShardNode> nodes;
  for (const auto& [node_id, count] : map->ShardsPerNode()) {
    ShardNode& node = nodes.emplace_back();
    node.node_id = node_id;
    node.shards = map->ShardsOf(node_id);
    MOTIONDB_ASSIGN_OR_RETURN(node.address,
                              AddressOf(node_id, node.shards.front(), map->epoch, refresh));
    refresh = false;  // one listing serves every node
  }
  return nodes;
}

absl::Status ClipRouter::ReserveName(const std::string& name, int64_t clip_id,
                                     const StillNamed& still_named) {
  const absl::Status reserved = names_.Reserve(name, clip_id);
  if (!absl::IsAlreadyExists(reserved)) return reserved;
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int64_t> holder, names_.Lookup(name));
  if (!holder) return names_.Reserve(name, clip_id);  // freed meanwhile
  if (*holder == clip_id) return absl::OkStatus();
  MOTIONDB_ASSIGN_OR_RETURN(const bool holds, still_named(*holder));
  if (holds) return reserved;
  MOTIONDB_ASSIGN_OR_RETURN(const bool moved, names_.Reassign(name, *holder, clip_id));
  return moved ? absl::OkStatus() : reserved;  // changed meanwhile: taken, as far as is known
}

absl::Status ClipRouter::ReleaseName(const std::string& name, int64_t clip_id) {
  return names_.Release(name, clip_id).status();
}

absl::Status ClipRouter::Settle(const std::string& name, const ClipRoute& route,
                                std::optional<int64_t> stored_clip_id) {
  if (!stored_clip_id) {
    if (route.held_by == 0) return ReleaseName(name, route.clip_id);
    return absl::OkStatus();
  }
  if (route.held_by != 0 && *stored_clip_id == route.clip_id) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool moved,
                              names_.Reassign(name, route.held_by, route.clip_id));
    if (moved) return absl::OkStatus();
    // Freed since the route was chosen (its clip deleted or renamed): the stored clip reserves it.
    const absl::Status reserved = names_.Reserve(name, route.clip_id);
    if (absl::IsAlreadyExists(reserved)) {
      return absl::AbortedError(absl::StrCat("clip ", route.clip_id, " was stored as '", name,
                                             "', which another clip reserved meanwhile (",
                                             reserved.message(), "): rename one of them"));
    }
    return reserved;
  }
  return absl::OkStatus();
}

}  // namespace motiondb::cluster
