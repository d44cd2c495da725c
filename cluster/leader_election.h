// A campaign for one named office of a cluster (the job coordinator, "jobs") among its routers,
// by etcd's own election recipe on its stable KV, Lease and Txn calls: the key
// /CLUSTER/elections/OFFICE holds the leader's node id under the leader's lease and is created
// only when absent. Each candidate renews its lease every third of the TTL on a thread of its own
// and with each renewal tries to create the key, or, leading, checks that it still holds it; so
// when the leader resigns or its lease expires, a waiting candidate takes the office within about
// a third of the TTL after the key goes.
//
// The guarantee: leading() is true only while the leader's lease surely lives (up to the TTL after
// the start of its last successful renewal; etcd, counting from when the renewal reached it,
// deletes the key no sooner), so two candidates never both see it true, short of their clocks'
// rates differing. on_change(false) runs at that instant when the thread is waiting, but when a
// call to etcd is in flight then, only once it fails (within the client's call_timeout): act on
// leading(), not on the last on_change. The limit: work begun while leading may still run after
// the lease ends; what must never overlap needs a fence in etcd as well.
//
// Thread-safe; `on_change` runs on the election's thread.
#ifndef MOTIONDB_CLUSTER_LEADER_ELECTION_H_
#define MOTIONDB_CLUSTER_LEADER_ELECTION_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/etcd_client.h"

namespace motiondb::cluster {

class LeaseKeeper;

class LeaderElection {
 public:
  // Campaigns for `office` of `cluster` as `node_id` (INVALID_ARGUMENT for a name CheckClusterName
  // refuses, or a TTL under a second, etcd's unit); its thread tries at once, so the server
  // starting it never waits on etcd, and etcd unreachable is no error: the campaign goes on
  // until it answers. `on_change` runs whenever leading() changes, on its thread. `etcd` must
  // outlive the election.
  static absl::StatusOr<std::unique_ptr<LeaderElection>> Start(
      const EtcdClient& etcd, const std::string& cluster, const std::string& office,
      const std::string& node_id, absl::Duration lease_ttl,
      std::function<void(bool leading)> on_change);
  // Resigns: stops campaigning, deletes the key if it still holds it and revokes the lease, so
  // that a waiting candidate takes the office at its next try. `on_change` does not run for it.
  ~LeaderElection();
  LeaderElection(const LeaderElection&) = delete;
  LeaderElection& operator=(const LeaderElection&) = delete;

  // Whether this candidate holds the office and its lease surely lives.
  bool leading() const;
  // The office's leader as etcd has it now (nullopt: none).
  absl::StatusOr<std::optional<std::string>> CurrentLeader() const;

 private:
  using Clock = std::chrono::steady_clock;

  LeaderElection(const EtcdClient& etcd, std::string key, std::string node_id,
                 absl::Duration lease_ttl, std::function<void(bool)> on_change);
  // Renews the lease, then tries for the office or checks that it still holds it.
  absl::Status Step();
  void Run();
  bool Stopping() const;
  // Leading no longer once the lease may have expired.
  void CheckLease();
  // `drop_lease` when the key may still be held under the lease (a renewal late, not lost).
  void Lose(bool drop_lease);
  void SetLeading(bool leading);

  const EtcdClient& etcd_;
  const std::string key_;
  const std::string node_id_;
  const absl::Duration lease_ttl_;
  const std::function<void(bool)> on_change_;
  // The thread's (and Start's, before it runs; the destructor's after):
  const std::unique_ptr<LeaseKeeper> lease_;
  int64_t revision_ = 0;  // the key's mod_revision while leading; 0 otherwise
  Clock::time_point stand_back_until_;
  bool reported_ = false;      // what on_change was last told
  bool last_step_ok_ = false;  // whether etcd answered the last step

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  Clock::time_point leading_until_ = Clock::time_point::min();  // guarded by mutex_
  bool stopping_ = false;                                       // guarded by mutex_
  std::thread thread_;
};

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_LEADER_ELECTION_H_
