// The listening port's credentials: plain text or TLS, and, when tokens are configured, a check
// of the calls to gRPC's own services (reflection; health with --health-needs-token) that
// refuses one without a valid "authorization: Bearer <token>" with UNAUTHENTICATED before it
// reaches the service. motiondb.v1's calls pass on to the service-side check
// (server/grpc/access_control.h), which knows the call's peer and the token's scope.
//
// The check is a C-core auth-metadata processor. The C++ API only lets one be attached to TLS
// credentials (grpc::InsecureServerCredentials() asserts in SetAuthMetadataProcessor, grpc issue
// #24278), and a server interceptor cannot refuse a call with a status of its choosing; the core
// supports the processor on insecure credentials too, so the credentials are built at that
// level.
#ifndef MOTIONDB_SERVER_GRPC_CREDENTIALS_H_
#define MOTIONDB_SERVER_GRPC_CREDENTIALS_H_

#include <memory>
#include <string>

#include <grpcpp/security/server_credentials.h>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/grpc/request_logger.h"

namespace motiondb::server {
class AccessControl;
}

namespace motiondb::server {

// TLS when both PEM strings are given, plain text when neither (INVALID_ARGUMENT for one
// alone); `access` without tokens means no authentication. With tokens, the health service
// (grpc.health.v1.Health) answers without one unless `health_needs_token`: probes
// (Kubernetes', load balancers') carry no credentials, and health says nothing about the data.
// Refused calls are told to `log`; `access` and `log` must outlive the credentials.
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const std::string& tls_cert_pem, const std::string& tls_key_pem, const AccessControl& access,
    bool health_needs_token, RequestLog& log);

// Whether a call of `method` ("/pkg.Service/Method") needs the token: every one but the health
// service's unless `health_needs_token`. The HTTP face's /healthz and /readyz follow it too.
bool MethodNeedsToken(absl::string_view method, bool health_needs_token);

// True when `header` is "Bearer <token>" (scheme case-insensitive, RFC 6750). Takes the same
// time for every header of a given length, so that the comparison does not leak the token.
bool BearerTokenMatches(absl::string_view header, absl::string_view token);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_CREDENTIALS_H_
