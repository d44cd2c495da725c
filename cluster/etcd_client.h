// A client of etcd's v3 API (KV, Txn, Lease, Watch, a member's status) in application terms: keys
// and values as strings, answers as absl::Status. Every call has a deadline
// (EtcdOptions::call_timeout) and goes on to the next member when one is down. Thread-safe.
#ifndef MOTIONDB_CLUSTER_ETCD_CLIENT_H_
#define MOTIONDB_CLUSTER_ETCD_CLIENT_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/etcd_options.h"
#include "cluster/etcd_watch.h"

namespace motiondb::cluster {

class EtcdChannels;

// A key as etcd stores it: revisions count every write to the store.
struct KeyValue {
  std::string key;
  std::string value;
  int64_t create_revision = 0;  // the write that created the key
  int64_t mod_revision = 0;     // the key's last write
  int64_t lease = 0;            // the lease it lives under; 0: none
};

// What a compare-and-swap did.
struct SwapOutcome {
  bool written = false;
  // When written: the revision of the write (the key's mod_revision now).
  int64_t revision = 0;
  // When not written: what the key holds now (nullopt: nothing).
  std::optional<KeyValue> current;
};

// What an etcd member says of itself.
struct MemberStatus {
  uint64_t member_id = 0;  // the member that answered
  uint64_t leader_id = 0;  // the raft leader it follows; 0 while there is none
  bool leads() const { return leader_id != 0 && leader_id == member_id; }
};

class EtcdClient {
 public:
  // INVALID_ARGUMENT without endpoints; connects lazily (a call to a member that is down fails
  // over, or fails with UNAVAILABLE when none answers).
  static absl::StatusOr<std::unique_ptr<EtcdClient>> Create(EtcdOptions options);
  ~EtcdClient();

  // The key, or nullopt when it is absent; by `deadline` if that is sooner than the call's
  // timeout (DEADLINE_EXCEEDED once it passes). A linearizable read: what etcd holds at some
  // instant during the call.
  absl::StatusOr<std::optional<KeyValue>> Get(const std::string& key,
                                              absl::Time deadline = absl::InfiniteFuture()) const;
  // Every key that begins with `prefix`, in key order.
  absl::StatusOr<std::vector<KeyValue>> Range(const std::string& prefix) const;
  // Writes `key` (under `lease` unless 0).
  absl::Status Put(const std::string& key, const std::string& value, int64_t lease = 0) const;
  absl::Status Delete(const std::string& key) const;
  // Writes `key` only when its mod_revision is still `expected_revision` (0: only when the key
  // is absent), in one transaction.
  absl::StatusOr<SwapOutcome> CompareAndSwap(const std::string& key, int64_t expected_revision,
                                             const std::string& value, int64_t lease = 0) const;
  // Deletes `key` only when its mod_revision is still `expected_revision` (> 0), in one
  // transaction: whether it did.
  absl::StatusOr<bool> DeleteIfRevision(const std::string& key, int64_t expected_revision) const;

  // A new lease of `ttl` (etcd rounds up to whole seconds and may raise it to its minimum).
  absl::StatusOr<int64_t> GrantLease(absl::Duration ttl) const;
  // Renews `lease` for its whole TTL and returns that TTL; NOT_FOUND when it has expired.
  absl::StatusOr<absl::Duration> KeepAlive(int64_t lease) const;
  // What is left of `lease`; NOT_FOUND when it has expired.
  absl::StatusOr<absl::Duration> TimeToLive(int64_t lease) const;
  // Ends `lease` now, deleting its keys.
  absl::Status RevokeLease(int64_t lease) const;

  // The status of the first member that answers (with one endpoint: that member's).
  absl::StatusOr<MemberStatus> Status() const;

  // Watches every key beginning with `prefix` (EtcdWatch).
  std::unique_ptr<EtcdWatch> Watch(const std::string& prefix, int64_t start_revision,
                                   EtcdWatch::Callbacks callbacks) const;

  const EtcdOptions& options() const;

 private:
  explicit EtcdClient(std::shared_ptr<const EtcdChannels> channels);
  std::shared_ptr<const EtcdChannels> channels_;
};

// The end of etcd's range holding every key that begins with `prefix`.
std::string PrefixRangeEnd(const std::string& prefix);

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_ETCD_CLIENT_H_
