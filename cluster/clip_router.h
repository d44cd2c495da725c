// Where a router sends the write of a clip by its name (ARCHITECTURE.md, "The cluster"): the
// clip's id, unique cluster-wide (ClipIdBlocks), its name reserved for it (ClipNames), and the
// node that holds the id's shard in the map as etcd holds it now. Thread-safe.
#ifndef MOTIONDB_CLUSTER_CLIP_ROUTER_H_
#define MOTIONDB_CLUSTER_CLIP_ROUTER_H_

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/clip_id_blocks.h"
#include "cluster/clip_names.h"
#include "cluster/etcd_client.h"
#include "cluster/shard_map.h"
#include "cluster/shard_map_watcher.h"

namespace motiondb::cluster {

struct ClipRoute {
  int64_t clip_id = 0;  // the id to store the clip under: never held by a clip before
  // The clip the name was reserved for already (its clip's shard is then the new id's, so that
  // the shard decides the conflict); 0: the name was free and is now reserved for clip_id.
  int64_t held_by = 0;
  int shard = 0;
  int64_t epoch = 0;    // of the map routed by
  std::string node_id;  // holding the shard
  std::string address;  // its gRPC face
};

// A node holding shards in the last map seen, and where it answers.
struct ShardNode {
  std::string node_id;
  std::string address;
  std::vector<int> shards;  // ascending
};

class ClipRouter {
 public:
  // `etcd` and `watcher` must outlive the router; `max_name_bytes` as ClipNames takes it.
  ClipRouter(const EtcdClient& etcd, const ShardMapWatcher& watcher, const std::string& cluster,
             size_t max_name_bytes);

  // Routes the clip named `name` to a new id. A free name is reserved for it. A name reserved
  // already keeps its clip's shard: the new id is the block's next on that shard, whose node
  // then decides the conflict as one node does (skip, refuse, or replace by the new id), so that a
  // name is stored on one shard only; Settle then moves the name to the id stored. Errors:
  // ClipIdBlocks::Next's and ClipNames::Reserve's; UNAVAILABLE when etcd cannot be read by
  // `deadline` or the node holding the shard is not live (naming both).
  absl::StatusOr<ClipRoute> Route(const std::string& name, absl::Time deadline);
  // After the shard's answer: the name follows a clip stored under the route's new id
  // (`stored_clip_id`, the answer's clip: a skip answers with the clip kept), or is freed when the
  // shard refused a clip whose name Route reserved (nullopt: only for a refusal that is sure, so
  // never for an answer lost on the way).
  absl::Status Settle(const std::string& name, const ClipRoute& route,
                      std::optional<int64_t> stored_clip_id);

  // Where clip `clip_id` is read: the node of its shard in the last map seen (so reads go on
  // while etcd is unreachable), at the address last listed for it (listed afresh from etcd when
  // the node is not among those known, or with `refresh`: after a call to it failed).
  // UNAVAILABLE before the first map, or when the node is not live; INVALID_ARGUMENT for an id
  // below 1.
  absl::StatusOr<ClipRoute> Locate(int64_t clip_id, bool refresh = false);
  // Every node the last map seen gives shards, in node id order, at the addresses last listed
  // (listed afresh from etcd with `refresh`, or when one is unknown): what a listing asks.
  // UNAVAILABLE before the first map, or when a node holding shards is not live (naming it).
  absl::StatusOr<std::vector<ShardNode>> ShardNodes(bool refresh = false);
  // Whether clip `clip_id` is still named as a reservation for it says (asked of its node): a
  // reservation left by a rename or a delete whose release failed is not.
  using StillNamed = std::function<absl::StatusOr<bool>(int64_t clip_id)>;
  // Reserves `name` for clip `clip_id` (a rename's new name), as ClipNames::Reserve; a name
  // reserved for another clip that `still_named` says is not named so any more is taken over.
  absl::Status ReserveName(const std::string& name, int64_t clip_id, const StillNamed& still_named);
  // Frees `name` if clip `clip_id` holds it (a deleted or renamed clip's), as ClipNames::Release.
  absl::Status ReleaseName(const std::string& name, int64_t clip_id);

 private:
  // The address of live node `node_id` (ListNodes into addresses_ when unknown or `refresh`).
  absl::StatusOr<std::string> AddressOf(const std::string& node_id, int shard, int64_t epoch,
                                        bool refresh);

  // Fills `route`'s shard, epoch, node and address for its clip_id in `map`.
  absl::Status RouteTo(const ShardMap& map, bool refresh, ClipRoute& route);
  // The last map seen; UNAVAILABLE before the first.
  absl::StatusOr<std::shared_ptr<const ShardMap>> LastMap() const;
  // The next id of the block on `shard` of `shard_count`; the ids passed over are never used.
  absl::StatusOr<int64_t> NextIdOnShard(int shard, int shard_count);

  const EtcdClient& etcd_;
  const ShardMapWatcher& watcher_;
  const std::string cluster_;
  ClipIdBlocks ids_;
  const ClipNames names_;
  std::mutex mutex_;
  std::map<std::string, std::string> addresses_;  // guarded by mutex_: node id -> address
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLIP_ROUTER_H_
