// The one place where the engine's absl::Status becomes the gRPC status a client sees (and
// where another node's gRPC status becomes an absl::Status).
#ifndef MOTIONDB_SERVER_GRPC_STATUS_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_STATUS_CONVERSION_H_

#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace motiondb::server {

// Same code (absl and gRPC both number them after google.rpc.Code), same message.
grpc::Status ToGrpcStatus(const absl::Status& status);
// The other way, for what another node answered (a cluster's router forwarding to a shard).
absl::Status FromGrpcStatus(const grpc::Status& status);

// "OK", "INVALID_ARGUMENT", ...: the names clients and logs use.
std::string StatusCodeName(grpc::StatusCode code);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_STATUS_CONVERSION_H_
