// The address a node registers, where routers and the CLI reach its gRPC face. A server
// listening on a wildcard (0.0.0.0:50051, [::]:50051) cannot register what it listens on: no
// other machine reaches "0.0.0.0". So a node advertises `--advertise` when given (a pod's DNS
// name behind a headless Service, say), else its listening host, a wildcard replaced by the
// machine's host name.
#ifndef MOTIONDB_CLUSTER_NODE_ADDRESS_H_
#define MOTIONDB_CLUSTER_NODE_ADDRESS_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb::cluster {

// `advertise` ("HOST" or "HOST:PORT"; an IPv6 literal in brackets, "[fd00::1]:7000"), a HOST
// alone taking `port`, the port served; or, when `advertise` is empty, `listen`'s host at `port`,
// `host_name` in place of a wildcard host. INVALID_ARGUMENT naming --advertise for a wildcard,
// an empty host, a host with spaces or a port outside 1-65535.
absl::StatusOr<std::string> AdvertisedAddress(absl::string_view advertise, absl::string_view listen,
                                              int port, absl::string_view host_name);

// This machine's host name (gethostname), or "localhost" when it has none.
std::string MachineHostName();

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_NODE_ADDRESS_H_
