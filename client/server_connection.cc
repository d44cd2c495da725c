#include "client/server_connection.h"

#include <cctype>
#include <chrono>
#include <cstdlib>
#include <regex>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "util/file_io.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"
#include "util/token_file.h"

namespace motiondb::cli {
namespace {

// A CA bundle is small; anything larger is a wrong path.
constexpr int64_t kMaxSecretFileBytes = int64_t{1} << 20;

absl::StatusOr<std::string> ResolveToken(const ConnectionOptions& options) {
  if (!options.token.empty()) return options.token;
  if (!options.token_file.empty()) return ReadTokenFile(options.token_file);
  if (const char* token = std::getenv("MOTIONDB_TOKEN"); token != nullptr && *token != '\0') {
    return std::string(token);
  }
  if (const char* file = std::getenv("MOTIONDB_TOKEN_FILE"); file != nullptr && *file != '\0') {
    return Prefixed("$MOTIONDB_TOKEN_FILE", ReadTokenFile(file));
  }
  return std::string();
}

// Field names are words of these characters: "training[0].last_frame".
bool IsFieldCharacter(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '[' ||
         c == ']';
}

// The flag of `field`, or of the list it indexes ("characteristic_frames[1]": the flag gives
// the whole list).
const std::string* FlagOf(const std::string& field, const FlagNames& flags) {
  for (const auto& [name, flag] : flags) {
    if (name == field) return &flag;
  }
  static const std::regex indexed(R"(([a-z_.]+)\[\d+\])");
  std::smatch match;
  if (std::regex_match(field, match, indexed)) return FlagOf(match.str(1), flags);
  return nullptr;
}

// "F is outside frames A..B" (the server's wording of a range check) with F past B.
std::string SayPastTheEnd(const std::string& message) {
  static const std::regex outside(R"((-?\d+) is outside (the clip's )?frames (-?\d+)\.\.(-?\d+))");
  std::smatch match;
  int64_t frame = 0, last = 0;
  if (!std::regex_search(message, match, outside) || !absl::SimpleAtoi(match.str(1), &frame) ||
      !absl::SimpleAtoi(match.str(4), &last) || frame <= last) {
    return message;
  }
  return absl::StrCat(match.prefix().str(), frame, " is past the clip's last frame ", last,
                      match.suffix().str());
}

}  // namespace

absl::StatusOr<ServerConnection> ServerConnection::Connect(const ConnectionOptions& options) {
  ServerConnection connection;
  connection.address_ = options.server;
  MOTIONDB_ASSIGN_OR_RETURN(connection.token_, ResolveToken(options));
  connection.timeout_s_ = options.timeout_s;
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (!options.tls_ca.empty()) {
    grpc::SslCredentialsOptions ssl;
    MOTIONDB_ASSIGN_OR_RETURN(ssl.pem_root_certs,
                              ReadFileBytes(options.tls_ca, kMaxSecretFileBytes));
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

std::string SpeakFlags(const std::string& message, const FlagNames& flags) {
  std::string spoken;
  for (size_t at = 0; at < message.size();) {
    size_t end = at;
    while (end < message.size() && IsFieldCharacter(message[end])) ++end;
    if (end == at) {
      spoken += message[at++];
      continue;
    }
    size_t word_end = end;  // a sentence's full stop is not part of the field
    while (word_end > at && message[word_end - 1] == '.') --word_end;
    const std::string word = message.substr(at, word_end - at);
    const std::string* flag = word.empty() ? nullptr : FlagOf(word, flags);
    if (flag == nullptr) {
      spoken.append(message, at, end - at);
      at = end;
      continue;
    }
    spoken += *flag;
    at = word_end;
    if (message.compare(at, 3, " = ") == 0) at += 2;  // "--max 0", not "--max = 0"
  }
  return SayPastTheEnd(spoken);
}

absl::Status Call(const ServerConnection& connection,
                  const std::function<grpc::Status(grpc::ClientContext*)>& rpc,
                  const FlagNames& flags) {
  const std::unique_ptr<grpc::ClientContext> context = connection.NewContext();
  const grpc::Status status = rpc(context.get());
  if (status.ok()) return absl::OkStatus();
  const grpc::Status spoken(status.error_code(), SpeakFlags(status.error_message(), flags));
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                      DescribeError(spoken, connection.address()));
}

}  // namespace motiondb::cli
