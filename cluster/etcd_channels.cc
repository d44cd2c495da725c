#include "cluster/internal/etcd_channels.h"

#include <chrono>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace motiondb::cluster {
namespace {

std::shared_ptr<grpc::Channel> MemberChannel(const std::string& endpoint) {
  grpc::ChannelArguments arguments;
  // gRPC's reconnect backoff grows to 2 minutes by default: a member back after a restart would
  // stay unused that long. etcd members are near; retry them within a second.
  arguments.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
  // Also each connection attempt's timeout (gRPC's default 20 s): a starting etcd accepts TCP
  // before it speaks HTTP/2, and a connection made then waited that long for its first frame.
  arguments.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 2000);
  arguments.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 1000);
  // A watch stream to a member that vanished without a reset (a cut cable) ends within about
  // 15 s; etcd accepts pings every 5 s or more (--grpc-keepalive-min-time).
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, 10'000);
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 5'000);
  return grpc::CreateCustomChannel(endpoint, grpc::InsecureChannelCredentials(), arguments);
}

bool MemberUnreachable(const grpc::Status& status) {
  return status.error_code() == grpc::StatusCode::UNAVAILABLE ||
         status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED;
}

}  // namespace

absl::StatusOr<std::vector<std::string>> ParseEtcdEndpoints(const std::string& text) {
  std::vector<std::string> endpoints;
  for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipWhitespace())) {
    part = absl::StripAsciiWhitespace(part);
    if (absl::StartsWith(part, "https://")) {
      return absl::InvalidArgumentError(
          absl::StrCat("etcd endpoint '", part, "': TLS to etcd is not supported yet"));
    }
    absl::ConsumePrefix(&part, "http://");
    absl::ConsumeSuffix(&part, "/");
    const size_t colon = part.rfind(':');
    if (colon == absl::string_view::npos || colon == 0 || colon + 1 == part.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat("etcd endpoint '", part, "': expected HOST:PORT, e.g. 127.0.0.1:2379"));
    }
    endpoints.emplace_back(part);
  }
  if (endpoints.empty()) {
    return absl::InvalidArgumentError("no etcd endpoint given (HOST:PORT, comma-separated)");
  }
  return endpoints;
}

absl::Status FromGrpc(const grpc::Status& status, const std::string& endpoint) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                      absl::StrCat("etcd at ", endpoint, ": ", status.error_message()));
}

EtcdChannels::EtcdChannels(EtcdOptions options) : options_(std::move(options)) {
  for (const std::string& endpoint : options_.endpoints) {
    channels_.push_back(MemberChannel(endpoint));
  }
}

void EtcdChannels::Failed(size_t member) const {
  size_t expected = member;
  current_.compare_exchange_strong(expected, (member + 1) % channels_.size());
}

absl::Status EtcdChannels::Call(
    const std::function<grpc::Status(const std::shared_ptr<grpc::Channel>&, grpc::ClientContext&)>&
        attempt,
    absl::Time call_deadline) const {
  const absl::Time deadline = std::min(call_deadline, absl::Now() + options_.call_timeout);
  // The caller's own deadline ending an attempt says nothing of the member: it is not failed
  // over, and the caller is told its deadline passed.
  const auto caller_deadline_passed = [&] {
    return absl::DeadlineExceededError(absl::StrCat("the call's deadline passed before etcd (",
                                                    absl::StrJoin(options_.endpoints, ","),
                                                    ") answered"));
  };
  absl::Status last = absl::UnavailableError("no member tried within the call's timeout");
  const size_t first = current_.load();
  for (size_t tried = 0; tried < channels_.size() && absl::Now() < deadline; ++tried) {
    const size_t member = (first + tried) % channels_.size();
    grpc::ClientContext context;
    context.set_deadline(
        absl::ToChronoTime(std::min(deadline, absl::Now() + options_.attempt_timeout)));
    const grpc::Status status = attempt(channels_[member], context);
    if (!MemberUnreachable(status)) return FromGrpc(status, options_.endpoints[member]);
    if (absl::Now() >= call_deadline) return caller_deadline_passed();
    last = FromGrpc(status, options_.endpoints[member]);
    Failed(member);
  }
  if (absl::Now() >= call_deadline) return caller_deadline_passed();
  return absl::UnavailableError(absl::StrCat(
      "etcd is unreachable (", absl::StrJoin(options_.endpoints, ","), "): ", last.message()));
}

}  // namespace motiondb::cluster
