#include "client/server_connection.h"

#include <chrono>
#include <cstdlib>
#include <iostream>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

// A CA bundle is small; anything larger is a wrong path.
constexpr int64_t kMaxCaBytes = int64_t{1} << 20;

}  // namespace

const std::set<std::string>& ConnectionOptions() {
  static const std::set<std::string> options = {"server", "token", "tls-ca", "timeout"};
  return options;
}

absl::StatusOr<ServerConnection> ServerConnection::Connect(const CommandLine& line) {
  ServerConnection connection;
  connection.address_ = line.value("server").value_or("127.0.0.1:50051");
  if (const std::optional<std::string> token = line.value("token")) {
    connection.token_ = *token;
  } else if (const char* env = std::getenv("MOTIONDB_TOKEN"); env != nullptr) {
    connection.token_ = env;
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> timeout, line.number("timeout"));
  if (timeout && *timeout <= 0) return absl::InvalidArgumentError("--timeout must be positive");
  connection.timeout_s_ = timeout.value_or(connection.timeout_s_);
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (const std::optional<std::string> ca = line.value("tls-ca")) {
    grpc::SslCredentialsOptions ssl;
    MOTIONDB_ASSIGN_OR_RETURN(ssl.pem_root_certs, ReadFileBytes(*ca, kMaxCaBytes));
    credentials = grpc::SslCredentials(ssl);
  }
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(-1);
  arguments.SetMaxSendMessageSize(-1);
  connection.channel_ = grpc::CreateCustomChannel(connection.address_, credentials, arguments);
  return connection;
}

std::unique_ptr<grpc::ClientContext> ServerConnection::NewContext() const {
  auto context = std::make_unique<grpc::ClientContext>();
  if (!token_.empty()) context->AddMetadata("authorization", absl::StrCat("Bearer ", token_));
  context->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::milliseconds(static_cast<int64_t>(timeout_s_ * 1000)));
  return context;
}

std::string DescribeError(const grpc::Status& status, const std::string& address) {
  const int code = static_cast<int>(status.error_code());
  // gRPC's and Abseil's codes are the same numbers with the same names.
  const std::string spelled = absl::StatusCodeToString(static_cast<absl::StatusCode>(code));
  const std::string name = spelled.empty() ? std::to_string(code) : spelled;
  if (status.error_code() == grpc::StatusCode::UNAVAILABLE) {
    return absl::StrCat("cannot reach the server at ", address, " (", status.error_message(),
                        "); is motiondb-server running? (--server ADDR)");
  }
  return absl::StrCat(name, ": ", status.error_message());
}

absl::Status Call(const ServerConnection& connection,
                  const std::function<grpc::Status(grpc::ClientContext*)>& rpc) {
  const std::unique_ptr<grpc::ClientContext> context = connection.NewContext();
  const grpc::Status status = rpc(context.get());
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                      DescribeError(status, connection.address()));
}

int RunServerCommand(
    const std::string& name, const std::string& usage, const std::vector<std::string>& args,
    std::set<std::string> value_options, const std::set<std::string>& flags,
    const std::function<absl::Status(const CommandLine&, const ServerConnection&)>& body) {
  value_options.insert(ConnectionOptions().begin(), ConnectionOptions().end());
  const absl::StatusOr<CommandLine> line = CommandLine::Parse(args, value_options, flags);
  absl::StatusOr<ServerConnection> connection =
      line.ok() ? ServerConnection::Connect(*line) : line.status();
  if (!connection.ok()) {
    std::cerr << "motiondb " << name << ": " << connection.status().message() << "\n"
              << "usage: " << usage << "\n";
    return 2;
  }
  const absl::Status status = body(*line, *connection);
  if (!status.ok()) {
    std::cerr << "motiondb " << name << ": " << status.message() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace motiondb::cli
