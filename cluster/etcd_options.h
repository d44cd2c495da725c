// Where etcd is and how long a call to it may take.
#ifndef MOTIONDB_CLUSTER_ETCD_OPTIONS_H_
#define MOTIONDB_CLUSTER_ETCD_OPTIONS_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"

namespace motiondb::cluster {

struct EtcdOptions {
  // The members' client addresses (host:port), tried in turn: a call that finds one down goes
  // on to the next.
  std::vector<std::string> endpoints;
  // Longest a call takes in all, over every endpoint it tries.
  absl::Duration call_timeout = absl::Seconds(5);
  // Longest one endpoint is given before the next is tried (a member cut off, not refusing).
  absl::Duration attempt_timeout = absl::Seconds(2);
};

// "http://a:2379,b:2379" -> {"a:2379", "b:2379"}: comma-separated host:port, each optionally
// with http:// (etcd's own notation). INVALID_ARGUMENT for none, an https:// one (no TLS to etcd
// yet) or one without a port.
absl::StatusOr<std::vector<std::string>> ParseEtcdEndpoints(const std::string& text);

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_ETCD_OPTIONS_H_
