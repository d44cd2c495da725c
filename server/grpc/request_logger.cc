#include "server/grpc/request_logger.h"

#include <unistd.h>

#include <chrono>
#include <string>

#include <grpcpp/server_context.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "server/grpc/status_conversion.h"

namespace motiondb::server {
namespace {

void WriteLine(const std::string& line) {
  // stderr is unbuffered, but a stream may split one line into several writes; one write(2) of
  // a short line is atomic with respect to other writers.
  const ssize_t written = ::write(STDERR_FILENO, line.data(), line.size());
  (void)written;  // nothing sensible to do when stderr is gone
}

std::string Now() {
  return absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::Now(), absl::UTCTimeZone());
}

class RequestLogger : public grpc::experimental::Interceptor {
 public:
  explicit RequestLogger(grpc::experimental::ServerRpcInfo* info)
      : info_(info), start_(std::chrono::steady_clock::now()) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    // The status is known when it is about to be sent; that is also where the call's work ends.
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::PRE_SEND_STATUS)) {
      const std::chrono::duration<double, std::milli> latency =
          std::chrono::steady_clock::now() - start_;
      LogRequest(info_->method(), methods->GetSendStatus().error_code(), latency.count(),
                 info_->server_context()->peer());
    }
    methods->Proceed();
  }

 private:
  grpc::experimental::ServerRpcInfo* info_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

void LogRequest(absl::string_view method, grpc::StatusCode code, double latency_ms,
                absl::string_view peer) {
  WriteLine(absl::StrFormat("%s %s %s %.2fms %s\n", Now(), method, StatusCodeName(code), latency_ms,
                            peer.empty() ? "-" : peer));
}

void LogLine(absl::string_view text) { WriteLine(absl::StrCat(Now(), " ", text, "\n")); }

grpc::experimental::Interceptor* RequestLoggerFactory::CreateServerInterceptor(
    grpc::experimental::ServerRpcInfo* info) {
  return new RequestLogger(info);
}

}  // namespace motiondb::server
