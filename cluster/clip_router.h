// Where a router sends the write of a clip by its name (ARCHITECTURE.md, "The cluster"): the
// clip's id, unique cluster-wide (ClipIdBlocks), its name reserved for it (ClipNames), and the
// node that holds the id's shard in the map as etcd holds it now. Thread-safe.
#ifndef MOTIONDB_CLUSTER_CLIP_ROUTER_H_
#define MOTIONDB_CLUSTER_CLIP_ROUTER_H_

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/clip_id_blocks.h"
#include "cluster/clip_names.h"
#include "cluster/etcd_client.h"
#include "cluster/shard_map_watcher.h"

namespace motiondb::cluster {

struct ClipRoute {
  int64_t clip_id = 0;
  bool name_was_held = false;  // the id is the clip's the name was reserved for already
  int shard = 0;
  int64_t epoch = 0;    // of the map routed by
  std::string node_id;  // holding the shard
  std::string address;  // its gRPC face
};

class ClipRouter {
 public:
  // `etcd` and `watcher` must outlive the router; `max_name_bytes` as ClipNames takes it.
  ClipRouter(const EtcdClient& etcd, const ShardMapWatcher& watcher, const std::string& cluster,
             size_t max_name_bytes);

  // Routes the clip named `name`. A name reserved already routes to the clip it was reserved
  // for, whose shard then decides the conflict as one node does (skip, refuse, or replace under
  // the same id): so a name is stored on one shard only, and a name whose store failed after its
  // reservation is stored there on the next try. A free name is reserved for a new id. Errors:
  // ClipIdBlocks::Next's and ClipNames::Reserve's; UNAVAILABLE when etcd cannot be read by
  // `deadline` or the node holding the shard is not live (naming both).
  absl::StatusOr<ClipRoute> Route(const std::string& name, absl::Time deadline);

 private:
  // The id `name` is reserved for, reserving it for a new id when it is free.
  absl::StatusOr<ClipRoute> ReserveName(const std::string& name);

  const EtcdClient& etcd_;
  const ShardMapWatcher& watcher_;
  const std::string cluster_;
  ClipIdBlocks ids_;
  const ClipNames names_;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLIP_ROUTER_H_
