#include "server/grpc/access_control.h"

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "server/grpc/credentials.h"
#include "server/grpc/method_scopes.h"

namespace motiondb::server {
namespace {

// What gRPC reports as the peer of an in-process call (the HTTP face's).
constexpr absl::string_view kInProcessPeer = "unknown";

std::optional<TokenScope> ScopeNamed(absl::string_view name) {
  for (const TokenScope scope :
       {TokenScope::kRead, TokenScope::kWrite, TokenScope::kAdmin, TokenScope::kCluster}) {
    if (TokenScopeName(scope) == name) return scope;
  }
  return std::nullopt;
}

class AccessInterceptor : public grpc::experimental::Interceptor {
 public:
  AccessInterceptor(grpc::experimental::ServerRpcInfo* info, AccessControl& access)
      : info_(info), access_(access) {}
  ~AccessInterceptor() override {
    if (noted_) access_.Forget(info_->server_context());
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::POST_RECV_INITIAL_METADATA) &&
        access_.enabled() && IsMotionDbMethod(info_->method())) {
      access_.Note(info_->server_context(), Decide(*methods->GetRecvInitialMetadata()));
      noted_ = true;
    }
    methods->Proceed();
  }

 private:
  AccessControl::Verdict Decide(const std::multimap<grpc::string_ref, grpc::string_ref>& metadata) {
    const grpc::ServerContextBase& context = *info_->server_context();
    if (context.peer() == kInProcessPeer) {
      // The HTTP face decided already; it says which scope it granted, for GetServerInfo.
      const auto given = metadata.find(kHttpScopeMetadata);
      const std::optional<TokenScope> scope =
          given == metadata.end()
              ? std::nullopt
              : ScopeNamed(absl::string_view(given->second.data(), given->second.size()));
      return {grpc::Status::OK, scope.value_or(TokenScope::kRead)};
    }
    std::vector<absl::string_view> authorization;
    const auto [first, last] = metadata.equal_range("authorization");
    for (auto it = first; it != last; ++it) {
      authorization.emplace_back(it->second.data(), it->second.size());
    }
    return access_.Decide(info_->method(), RequiredScope(info_->method()),
                          AddressOfPeer(context.peer()), authorization,
                          "send the metadata 'authorization: Bearer <token>'");
  }

  grpc::experimental::ServerRpcInfo* info_;
  AccessControl& access_;
  bool noted_ = false;
};

}  // namespace

AccessControl::AccessControl(AccessOptions options)
    : options_(std::move(options)), failures_(options_.max_failures, options_.failure_window) {}

std::optional<TokenScope> AccessControl::ScopeOf(
    const std::vector<absl::string_view>& authorization) const {
  std::optional<TokenScope> widest;
  for (const absl::string_view header : authorization) {
    for (const ScopedToken& token : options_.tokens) {
      if (BearerTokenMatches(header, token.token) && (!widest || token.scope > *widest)) {
        widest = token.scope;
      }
    }
  }
  return widest;
}

AccessControl::Verdict AccessControl::Decide(absl::string_view what, TokenScope needed,
                                             absl::string_view address,
                                             const std::vector<absl::string_view>& authorization,
                                             absl::string_view how_to_send) {
  if (!enabled()) return {grpc::Status::OK, TokenScope::kAdmin};
  if (const std::chrono::seconds blocked = failures_.Blocked(address); blocked.count() > 0) {
    return {
        grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                     absl::StrCat("too many failed authentications from ", address, " (",
                                  failures_.max_failures(), " in ", options_.failure_window.count(),
                                  " s); retry in ", blocked.count(), " s")),
        TokenScope::kRead};
  }
  const std::optional<TokenScope> scope = ScopeOf(authorization);
  if (!scope) {
    failures_.Fail(address);
    return {grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                         absl::StrCat("missing or wrong bearer token: ", how_to_send)),
            TokenScope::kRead};
  }
  if (*scope < needed) {
    return {grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                         absl::StrCat("this token's scope is '", TokenScopeName(*scope), "'; ",
                                      what, " needs '", TokenScopeName(needed), "'")),
            *scope};
  }
  return {grpc::Status::OK, *scope};
}

void AccessControl::Note(const grpc::ServerContextBase* call, Verdict verdict) {
  std::lock_guard<std::mutex> lock(mutex_);
  calls_[call] = std::move(verdict);
}

void AccessControl::Forget(const grpc::ServerContextBase* call) {
  std::lock_guard<std::mutex> lock(mutex_);
  calls_.erase(call);
}

AccessControl::Verdict AccessControl::VerdictOf(const grpc::ServerContextBase* call) const {
  if (!enabled()) return {grpc::Status::OK, TokenScope::kAdmin};
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = calls_.find(call);
  if (found != calls_.end()) return found->second;
  return {grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "the call was not authenticated"),
          TokenScope::kRead};
}

std::string AddressOfPeer(absl::string_view peer) {
  absl::string_view address = peer;
  if (absl::ConsumePrefix(&address, "ipv6:")) {
    address = address.substr(0, address.rfind(':'));  // the port
    absl::ConsumePrefix(&address, "[");
    absl::ConsumeSuffix(&address, "]");
    if (absl::StartsWith(address, "::ffff:") && absl::StrContains(address, '.')) {
      address.remove_prefix(7);
    }
    return std::string(address);
  }
  if (absl::ConsumePrefix(&address, "ipv4:"))
    return std::string(address.substr(0, address.rfind(':')));
  return std::string(peer);
}

grpc::experimental::Interceptor* AccessInterceptorFactory::CreateServerInterceptor(
    grpc::experimental::ServerRpcInfo* info) {
  return new AccessInterceptor(info, access_);
}

}  // namespace motiondb::server
