// Who may call what: the bearer token a call carries, the scope it grants (util/token_file.h)
// against the scope the method needs (server/grpc/method_scopes.h), and the client addresses
// whose failed attempts are too many (server/grpc/auth_failure_limiter.h). Both faces decide
// here: the HTTP face from a request's head, before its body is read; the gRPC face in the
// service, where the call's peer is known (the port's C-core auth processor sees no peer, so
// it only guards gRPC's own services): AccessInterceptor decides when a call's metadata
// arrives, and the call gate (server/grpc/call_gate.h) refuses it before it runs. A refused gRPC
// call's log line names its peer like any other.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_GRPC_ACCESS_CONTROL_H_
#define MOTIONDB_SERVER_GRPC_ACCESS_CONTROL_H_

#include <chrono>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <grpcpp/server_context.h>
#include <grpcpp/support/server_interceptor.h>
#include <grpcpp/support/status.h>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/string_view.h"
#include "server/grpc/auth_failure_limiter.h"
#include "util/token_file.h"

namespace motiondb::server {

// The metadata by which the HTTP face tells its in-process calls the scope it granted; believed
// only on in-process calls, which only the HTTP face makes.
inline constexpr char kHttpScopeMetadata[] = "x-motiondb-http-scope";

struct AccessOptions {
  std::vector<ScopedToken> tokens;  // none: every call may do everything
  // Failed authentications one client address may make in `failure_window` before it is
  // refused for the rest of it.
  int max_failures = 10;
  std::chrono::seconds failure_window{60};
};

class AccessControl {
 public:
  struct Verdict {
    grpc::Status status;  // OK, UNAUTHENTICATED, PERMISSION_DENIED or RESOURCE_EXHAUSTED
    TokenScope scope = TokenScope::kAdmin;  // what the caller holds (when status is OK)
  };

  explicit AccessControl(AccessOptions options);

  bool enabled() const { return !options_.tokens.empty(); }
  // The widest scope that one of `authorization` ("Bearer <token>" header values) grants;
  // nullopt when none matches. Every token is compared with every value, in time that depends
  // only on their lengths.
  std::optional<TokenScope> ScopeOf(const std::vector<absl::string_view>& authorization) const;
  // Whether a caller from `address` (no port) carrying `authorization` may do `what` (a gRPC
  // method or an HTTP route, for the message), which needs `needed`. A failed authentication is
  // counted against the address. `how_to_send` ends the refusal of a missing or wrong token
  // ("send the header 'Authorization: Bearer <token>'").
  Verdict Decide(absl::string_view what, TokenScope needed, absl::string_view address,
                 const std::vector<absl::string_view>& authorization,
                 absl::string_view how_to_send);

  // The verdicts of gRPC calls under way, by call: noted by AccessInterceptor, read by the call
  // gate. A call never noted is refused (UNAUTHENTICATED), as one that slipped past the check.
  void Note(const grpc::ServerContextBase* call, Verdict verdict);
  void Forget(const grpc::ServerContextBase* call);
  Verdict VerdictOf(const grpc::ServerContextBase* call) const;

 private:
  const AccessOptions options_;
  AuthFailureLimiter failures_;
  mutable std::mutex mutex_;
  absl::flat_hash_map<const grpc::ServerContextBase*, Verdict> calls_;  // guarded by mutex_
};

// "1.2.3.4" of gRPC's peer "ipv4:1.2.3.4:5678" ("::1" of "ipv6:[::1]:5678"; an IPv4-mapped IPv6
// address as IPv4, as the listener counts it).
std::string AddressOfPeer(absl::string_view peer);

// Decides every motiondb.v1 call when its metadata arrives (see AccessControl).
class AccessInterceptorFactory : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit AccessInterceptorFactory(AccessControl& access) : access_(access) {}
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override;

 private:
  AccessControl& access_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_ACCESS_CONTROL_H_
