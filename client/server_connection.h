// How the CLI reaches a motiondb server: --server ADDR (default $MOTIONDB_SERVER, else
// 127.0.0.1:50051), a bearer token
// (sent as "authorization: Bearer T"), --tls-ca FILE (TLS, verifying the server against that CA
// certificate), --timeout SECONDS per call; and how the server's errors are told in the CLI's
// words.
#ifndef MOTIONDB_CLIENT_SERVER_CONNECTION_H_
#define MOTIONDB_CLIENT_SERVER_CONNECTION_H_

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/status/statusor.h"

namespace motiondb::cli {

// What the connection flags say (client/commands.cc registers them).
struct ConnectionOptions {
  std::string server = "127.0.0.1:50051";
  // The token is --token; else the contents of --token-file; else $MOTIONDB_TOKEN; else the
  // contents of the file $MOTIONDB_TOKEN_FILE names (a file's surrounding whitespace ignored).
  std::string token;
  std::string token_file;
  std::string tls_ca;  // empty: no TLS
  double timeout_s = 600;
};

class ServerConnection {
 public:
  static absl::StatusOr<ServerConnection> Connect(const ConnectionOptions& options);

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

// The command-line words that set a request's fields, for the server's errors, which name the
// fields: {"clip.last_frame", "--to"}, {"training[0]", "--train 12:0-400"}.
using FlagNames = std::vector<std::pair<std::string, std::string>>;
// `message` with each field of `flags` (a whole word) replaced by its words, "FIELD = V" said
// as "FLAG V", and a frame "F is outside frames A..B" past the end said as "F is past the
// clip's last frame B".
std::string SpeakFlags(const std::string& message, const FlagNames& flags);

// Runs one RPC with a fresh context; a failure becomes an absl::Status carrying the gRPC code
// and DescribeError's text, told in `flags`' words.
absl::Status Call(const ServerConnection& connection,
                  const std::function<grpc::Status(grpc::ClientContext*)>& rpc,
                  const FlagNames& flags = {});

// One unary RPC of a generated stub, e.g. CallUnary(connection, &v1::ClipService::Stub::GetClip,
// request): its answer, or Call's error.
template <typename Stub, typename Request, typename Response>
absl::StatusOr<Response> CallUnary(const ServerConnection& connection,
                                   grpc::Status (Stub::*rpc)(grpc::ClientContext*, const Request&,
                                                             Response*),
                                   const Request& request, const FlagNames& flags = {}) {
  Stub stub(connection.channel());
  Response response;
  const absl::Status status = Call(
      connection,
      [&](grpc::ClientContext* context) { return (stub.*rpc)(context, request, &response); },
      flags);
  if (!status.ok()) return status;
  return response;
}

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_SERVER_CONNECTION_H_
