#include "server/grpc/request_logger.h"

#include <unistd.h>

#include <chrono>
#include <string>

#include <google/protobuf/descriptor.h>
#include <grpcpp/server_context.h>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/strip.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "server/grpc/status_conversion.h"

namespace motiondb::server {
namespace {

void Write(const std::string& line) {
  // stderr is unbuffered, but a stream may split one line into several writes; one write(2) of
  // a short line is atomic with respect to other writers.
  const ssize_t written = ::write(STDERR_FILENO, line.data(), line.size());
  (void)written;  // nothing sensible to do when stderr is gone
}

std::string Now() {
  return absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::Now(), absl::UTCTimeZone());
}

// What gRPC reports as the peer of a call that has none.
constexpr absl::string_view kNoPeer = "unknown";

// "/pkg.Service/Method" when a service linked into this process has it, else "unknown", so that
// the metrics' label values stay few whatever paths clients send.
std::string MethodLabel(absl::string_view method) {
  absl::string_view name = method;
  if (!absl::ConsumePrefix(&name, "/")) return "unknown";
  const std::string full_name = absl::StrReplaceAll(name, {{"/", "."}});
  return google::protobuf::DescriptorPool::generated_pool()->FindMethodByName(full_name) != nullptr
             ? std::string(method)
             : "unknown";
}

class RequestLogger : public grpc::experimental::Interceptor {
 public:
  RequestLogger(grpc::experimental::ServerRpcInfo* info, RequestLog& log)
      : info_(info), log_(log), start_(std::chrono::steady_clock::now()) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    // The status is known when it is about to be sent; that is also where the call's work ends.
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::PRE_SEND_STATUS)) {
      const std::chrono::duration<double, std::milli> latency =
          std::chrono::steady_clock::now() - start_;
      const grpc::ServerContextBase& context = *info_->server_context();
      std::string peer = context.peer();
      absl::string_view face = kGrpcFace;
      // Only the HTTP face calls in-process (grpc::Server::InProcessChannel), whose transport
      // (gRPC 1.51) gives no peer: network peers are "ipv4:...", "ipv6:..." or "unix:...".
      if (peer == kNoPeer) {
        face = kHttpFace;
        const auto given = context.client_metadata().find(kHttpPeerMetadata);
        peer = absl::StrCat("http:",
                            given == context.client_metadata().end()
                                ? "-"
                                : absl::string_view(given->second.data(), given->second.size()));
      }
      const grpc::Status status = methods->GetSendStatus();
      log_.Record(face, info_->method(), status.error_code(), latency.count(), peer,
                  status.error_message());
    }
    methods->Proceed();
  }

 private:
  grpc::experimental::ServerRpcInfo* info_;
  RequestLog& log_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

void LogLine(absl::string_view text) { Write(absl::StrCat(Now(), " ", text, "\n")); }

void RequestLog::Record(absl::string_view face, absl::string_view method, grpc::StatusCode code,
                        double latency_ms, absl::string_view peer, absl::string_view message) {
  const std::string code_name = StatusCodeName(code);
  metrics_.CountCall(face, MethodLabel(method), code_name, latency_ms / 1000);
  // What the operator must act on (a full disk, a damaged file, a limit reached) is told with
  // its reason; a client's own mistakes are told to the client only.
  const bool server_side =
      code == grpc::StatusCode::RESOURCE_EXHAUSTED || code == grpc::StatusCode::INTERNAL ||
      code == grpc::StatusCode::UNKNOWN || code == grpc::StatusCode::DATA_LOSS ||
      code == grpc::StatusCode::UNAVAILABLE;
  WriteLine(method, code_name, latency_ms, peer, server_side ? message : "");
}

void RequestLog::WriteLine(absl::string_view what, absl::string_view outcome, double latency_ms,
                           absl::string_view peer, absl::string_view reason) {
  if (!write_lines_) return;
  constexpr size_t kMaxReason = 300;
  Write(absl::StrFormat(
      "%s %s %s %.2fms %s%s\n", Now(), what, outcome, latency_ms, peer.empty() ? "-" : peer,
      // Escaped, so that a message cannot split or forge a line.
      reason.empty() ? ""
                     : absl::StrCat(" \"", absl::CHexEscape(reason.substr(0, kMaxReason)),
                                    reason.size() > kMaxReason ? "..." : "", "\"")));
}

grpc::experimental::Interceptor* RequestLoggerFactory::CreateServerInterceptor(
    grpc::experimental::ServerRpcInfo* info) {
  return new RequestLogger(info, log_);
}

}  // namespace motiondb::server
