// motiondb-server: the networked motion-search database.
//
//   motiondb-server [--db ./motiondb.sqlite] [--listen 127.0.0.1:50051] [--threads N]
//       [--max-message-mb 256] [--max-bvh-mb 1024] [--auth-token-file FILE]
//       [--tls-cert CERT.pem --tls-key KEY.pem] [--quiet]
//
// Runs until SIGTERM or SIGINT, then stops accepting calls, lets running ones finish (up to 10 s)
// and exits 0.
#include <signal.h>

#include <chrono>
#include <iostream>
#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "server/grpc/motiondb_server.h"
#include "server/grpc/request_logger.h"
#include "server/grpc/server_options.h"
#include "util/command_line.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace {

constexpr char kUsage[] =
    "usage: motiondb-server [--db FILE] [--listen HOST:PORT] [--threads N]\n"
    "           [--max-message-mb 256] [--max-bvh-mb 1024] [--auth-token-file FILE]\n"
    "           [--tls-cert CERT.pem --tls-key KEY.pem] [--quiet]\n"
    "  --db               SQLite database, created when missing (default ./motiondb.sqlite)\n"
    "  --listen           address to serve on (default 127.0.0.1:50051; port 0 picks one)\n"
    "  --threads          most calls handled at once; more are refused with\n"
    "                     RESOURCE_EXHAUSTED (default: no limit)\n"
    "  --max-message-mb   largest request message (default 256)\n"
    "  --max-bvh-mb       largest BVH upload, streamed or not (default 1024)\n"
    "  --auth-token-file  require 'authorization: Bearer <token>' on every call, the token\n"
    "                     being this file's contents (surrounding whitespace ignored)\n"
    "  --tls-cert/--tls-key  serve TLS with this PEM certificate chain and private key\n"
    "  --quiet            no per-request log lines\n";

// Secrets and certificates are small; anything larger is a wrong path.
constexpr int64_t kMaxSecretFileBytes = int64_t{1} << 20;
// How long running calls may finish after SIGTERM/SIGINT before they are cancelled.
constexpr std::chrono::seconds kShutdownGrace(10);

absl::StatusOr<std::string> ReadToken(const std::string& path) {
  MOTIONDB_ASSIGN_OR_RETURN(std::string text, motiondb::ReadFileBytes(path, kMaxSecretFileBytes));
  const std::string token(absl::StripAsciiWhitespace(text));
  if (token.empty()) return absl::InvalidArgumentError(absl::StrCat(path, ": the token is empty"));
  for (const char c : token) {
    // The token travels in an HTTP/2 header value.
    if (!absl::ascii_isgraph(static_cast<unsigned char>(c))) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": the token must be printable ASCII without spaces"));
    }
  }
  return token;
}

absl::StatusOr<motiondb::server::ServerOptions> ParseOptions(
    const motiondb::cli::CommandLine& line) {
  motiondb::server::ServerOptions options;
  if (!line.positionals().empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("unexpected argument '", line.positionals()[0], "'"));
  }
  options.db_path = line.value("db").value_or(options.db_path);
  options.listen = line.value("listen").value_or(options.listen);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> threads, line.integer("threads"));
  options.threads = threads.value_or(options.threads);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> message_mb, line.integer("max-message-mb"));
  options.max_message_mb = message_mb.value_or(options.max_message_mb);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> bvh_mb, line.integer("max-bvh-mb"));
  if (bvh_mb) {
    if (*bvh_mb < 1) return absl::InvalidArgumentError("--max-bvh-mb must be at least 1");
    options.uploads.max_bvh_bytes = int64_t{*bvh_mb} << 20;
  }
  if (const std::optional<std::string> path = line.value("auth-token-file")) {
    MOTIONDB_ASSIGN_OR_RETURN(options.auth_token, ReadToken(*path));
  }
  const std::optional<std::string> cert = line.value("tls-cert");
  const std::optional<std::string> key = line.value("tls-key");
  if (cert.has_value() != key.has_value()) {
    return absl::InvalidArgumentError("give both --tls-cert and --tls-key, or neither");
  }
  if (cert) {
    MOTIONDB_ASSIGN_OR_RETURN(options.tls_cert_pem,
                              motiondb::ReadFileBytes(*cert, kMaxSecretFileBytes));
    MOTIONDB_ASSIGN_OR_RETURN(options.tls_key_pem,
                              motiondb::ReadFileBytes(*key, kMaxSecretFileBytes));
  }
  options.log_requests = !line.flag("quiet");
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  // Block the stop signals before any thread exists (gRPC's threads inherit the mask), so that
  // only sigwait() below receives them, outside of any signal handler.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a vanished client must not kill the server

  const std::vector<std::string> args(argv + 1, argv + argc);
  const absl::StatusOr<motiondb::cli::CommandLine> line =
      motiondb::cli::CommandLine::Parse(args,
                                        {"db", "listen", "threads", "max-message-mb", "max-bvh-mb",
                                         "auth-token-file", "tls-cert", "tls-key"},
                                        {"quiet", "help"});
  if (line.ok() && line->flag("help")) {
    std::cout << kUsage;
    return 0;
  }
  absl::StatusOr<motiondb::server::ServerOptions> options =
      line.ok() ? ParseOptions(*line)
                : absl::StatusOr<motiondb::server::ServerOptions>(line.status());
  if (!options.ok()) {
    std::cerr << "motiondb-server: " << options.status().message() << "\n" << kUsage;
    return 2;
  }
  absl::StatusOr<std::unique_ptr<motiondb::server::MotionDbServer>> server =
      motiondb::server::MotionDbServer::Start(*options);
  if (!server.ok()) {
    std::cerr << "motiondb-server: " << server.status().message() << "\n";
    return 1;
  }
  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  motiondb::server::LogLine(absl::StrCat(
      "received ", signal_number == SIGTERM ? "SIGTERM" : "SIGINT", "; shutting down"));
  (*server)->Shutdown(std::chrono::system_clock::now() + kShutdownGrace);
  (*server)->Wait();
  server->reset();
  motiondb::server::LogLine("stopped");
  return 0;
}
