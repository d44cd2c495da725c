// A lease kept alive by its owner's thread (NodeRegistration, LeaderElection): renewed while it
// lives, replaced by a new one when it has expired, revoked when the keeper goes. Not
// thread-safe: one thread at a time (the owner's thread, or its owner before and after it runs).
#ifndef MOTIONDB_CLUSTER_INTERNAL_LEASE_KEEPER_H_
#define MOTIONDB_CLUSTER_INTERNAL_LEASE_KEEPER_H_

#include <chrono>
#include <cstdint>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/etcd_client.h"

namespace motiondb::cluster {

class LeaseKeeper {
 public:
  // `etcd` must outlive the keeper. No lease is taken before the first Renew.
  LeaseKeeper(const EtcdClient& etcd, absl::Duration ttl);
  // Revokes the lease, so that its keys go at once rather than at expiry.
  ~LeaseKeeper();
  LeaseKeeper(const LeaseKeeper&) = delete;
  LeaseKeeper& operator=(const LeaseKeeper&) = delete;

  // Renews the lease or, when none is held or it has expired (etcd away too long, or the lease
  // revoked by someone else), takes a new one: whether the lease is new, so that the keys meant to
  // live under it must be written again.
  absl::StatusOr<bool> Renew();
  // Revokes the lease now and forgets it: the next Renew takes a new one.
  void Drop();

  int64_t id() const { return id_; }
  // Until when the lease surely lives: the start of the last successful Renew plus the TTL (the
  // TTL asked for at a grant, which etcd may only raise; the TTL etcd gives at a renewal). etcd
  // counts it from when it received the call, later than its start here. The epoch once dropped.
  std::chrono::steady_clock::time_point surely_until() const { return surely_until_; }

 private:
  const EtcdClient& etcd_;
  const absl::Duration ttl_;
  int64_t id_ = 0;  // 0: none
  std::chrono::steady_clock::time_point surely_until_;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_INTERNAL_LEASE_KEEPER_H_
