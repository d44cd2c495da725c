// How the CLI reaches a motiondb server: --server ADDR (default 127.0.0.1:50051), --token T or
// the MOTIONDB_TOKEN environment variable (sent as "authorization: Bearer T"), --tls-ca FILE
// (TLS, verifying the server against that CA certificate), --timeout SECONDS per call.
#ifndef MOTIONDB_CLIENT_SERVER_CONNECTION_H_
#define MOTIONDB_CLIENT_SERVER_CONNECTION_H_

#include <functional>
#include <memory>
#include <set>
#include <string>

#include <grpcpp/grpcpp.h>

#include "absl/status/statusor.h"
#include "util/command_line.h"

namespace motiondb::cli {

// The value options every server command accepts.
const std::set<std::string>& ConnectionOptions();

class ServerConnection {
 public:
  static absl::StatusOr<ServerConnection> Connect(const CommandLine& line);

  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }
  const std::string& address() const { return address_; }
  // A context for one call, carrying the token and the deadline.
  std::unique_ptr<grpc::ClientContext> NewContext() const;

 private:
  std::shared_ptr<grpc::Channel> channel_;
  std::string address_;
  std::string token_;
  double timeout_s_ = 600;
};

// "CODE_NAME: message", e.g. "INVALID_ARGUMENT: line 12: expected ..."; names the server when
// it cannot be reached.
std::string DescribeError(const grpc::Status& status, const std::string& address);

// Runs one RPC with a fresh context; a failure becomes an absl::Status carrying the gRPC code
// and DescribeError's text.
absl::Status Call(const ServerConnection& connection,
                  const std::function<grpc::Status(grpc::ClientContext*)>& rpc);

// The shape every server command shares: parse `args` (with the connection options added to
// `value_options`), connect, run `body`; errors print as "motiondb NAME: message" (plus the
// usage when the command line cannot be parsed). Returns the process exit code: 0, 1 for a
// failed command, 2 for a bad command line.
int RunServerCommand(
    const std::string& name, const std::string& usage, const std::vector<std::string>& args,
    std::set<std::string> value_options, const std::set<std::string>& flags,
    const std::function<absl::Status(const CommandLine&, const ServerConnection&)>& body);

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_SERVER_CONNECTION_H_
