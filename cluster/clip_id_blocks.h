// Cluster-wide unique clip ids, so that an id alone names its shard (ShardOfClip): a router hands
// them out of blocks it reserves from the counter /CLUSTER/next_clip_id by compare-and-swap on
// the key's revision, and reserves the next block only when its block is used up. Ids left
// unused in a block when its router dies or restarts are skipped: never handed out, never reused.
// Thread-safe.
#ifndef MOTIONDB_CLUSTER_CLIP_ID_BLOCKS_H_
#define MOTIONDB_CLUSTER_CLIP_ID_BLOCKS_H_

#include <cstdint>
#include <mutex>
#include <string>

#include "absl/status/statusor.h"
#include "cluster/etcd_client.h"

namespace motiondb::cluster {

class ClipIdBlocks {
 public:
  // One etcd transaction every thousand ingests; what a dead router skips is nothing to int64.
  static constexpr int64_t kDefaultBlockSize = 1000;

  // `etcd` must outlive the blocks; `block_size` >= 1.
  ClipIdBlocks(const EtcdClient& etcd, const std::string& cluster,
               int64_t block_size = kDefaultBlockSize);

  // The next id of the block held, reserving a new block first when it is used up (or none is
  // held yet). UNAVAILABLE while etcd is unreachable; ABORTED when other routers changed the
  // counter under every attempt of a reservation; FAILED_PRECONDITION, naming the key, when the
  // counter holds no positive number; RESOURCE_EXHAUSTED past int64's ids; INVALID_ARGUMENT for a
  // block size under 1. A counter deleted by hand starts again at 1: ids then repeat, so the key
  // is never to be touched but by this class.
  absl::StatusOr<int64_t> Next();

 private:
  absl::Status ReserveBlock();  // with mutex_ held

  const EtcdClient& etcd_;
  const std::string key_;
  const int64_t block_size_;
  std::mutex mutex_;  // held through a reservation: the threads waiting need its block anyway
  int64_t next_ = 0;  // guarded by mutex_: the block's next id to hand out
  int64_t end_ = 0;   // guarded by mutex_: one past the block's last id
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_CLIP_ID_BLOCKS_H_
