#include "cluster/internal/lease_keeper.h"

#include "util/status_macros.h"

namespace motiondb::cluster {

LeaseKeeper::LeaseKeeper(const EtcdClient& etcd, absl::Duration ttl) : etcd_(etcd), ttl_(ttl) {}

LeaseKeeper::~LeaseKeeper() { Drop(); }

absl::StatusOr<bool> LeaseKeeper::Renew() {
  const auto start = std::chrono::steady_clock::now();
  if (id_ != 0) {
    const absl::StatusOr<absl::Duration> renewed = etcd_.KeepAlive(id_);
    if (renewed.ok()) {
      surely_until_ = start + absl::ToChronoMilliseconds(*renewed);
      return false;
    }
    if (!absl::IsNotFound(renewed.status())) return renewed.status();
    id_ = 0;  // expired while etcd was away or this process was stopped
  }
  // etcd may raise the TTL asked for, never lower it.
  MOTIONDB_ASSIGN_OR_RETURN(id_, etcd_.GrantLease(ttl_));
  surely_until_ = start + absl::ToChronoMilliseconds(ttl_);
  return true;
}

void LeaseKeeper::Drop() {
  if (id_ != 0) etcd_.RevokeLease(id_).IgnoreError();  // else it expires within its TTL
  id_ = 0;
  surely_until_ = {};
}

}  // namespace motiondb::cluster
