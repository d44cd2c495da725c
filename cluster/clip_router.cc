#include "cluster/clip_router.h"

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

absl::StatusOr<ClipRoute> ClipRouter::ReserveName(const std::string& name) {
  ClipRoute route;
  MOTIONDB_ASSIGN_OR_RETURN(std::optional<int64_t> held, names_.Lookup(name));
  if (!held) {
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t id, ids_.Next());
    const absl::Status reserved = names_.Reserve(name, id);
    if (reserved.ok()) {
      route.clip_id = id;
      return route;
    }
    if (!absl::IsAlreadyExists(reserved)) return reserved;
    // Another router reserved it since the lookup: the id it was given is the clip's.
    MOTIONDB_ASSIGN_OR_RETURN(held, names_.Lookup(name));
    if (!held) {
      return absl::AbortedError(
          absl::StrCat("clip name '", name, "' was reserved and freed meanwhile; try again"));
    }
  }
  route.clip_id = *held;
  route.name_was_held = true;
  return route;
}

absl::StatusOr<ClipRoute> ClipRouter::Route(const std::string& name, absl::Time deadline) {
  MOTIONDB_ASSIGN_OR_RETURN(ClipRoute route, ReserveName(name));
  MOTIONDB_ASSIGN_OR_RETURN(const ShardMap map, watcher_.CurrentMap(deadline));
  route.shard = ShardOfClip(route.clip_id, map.shard_count());
  route.epoch = map.epoch;
  route.node_id = map.owners[route.shard];
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<NodeInfo> nodes, ListNodes(etcd_, cluster_));
  for (const NodeInfo& node : nodes) {
    if (node.node_id == route.node_id) {
      route.address = node.address;
      return route;
    }
  }
  return absl::UnavailableError(absl::StrCat("shard ", route.shard, "'s node '", route.node_id,
                                             "' is not live (map epoch ", map.epoch, ")"));
}

}  // namespace motiondb::cluster
