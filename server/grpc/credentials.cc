#include "server/grpc/credentials.h"

#include <grpc/grpc_security.h>

#include <vector>

#include "absl/strings/match.h"
#include "server/grpc/access_control.h"
#include "server/grpc/method_scopes.h"
#include "server/grpc/request_logger.h"

namespace motiondb::server {
namespace {

absl::string_view SliceView(const grpc_slice& slice) {
  return absl::string_view(reinterpret_cast<const char*>(GRPC_SLICE_START_PTR(slice)),
                           GRPC_SLICE_LENGTH(slice));
}

struct TokenCheck {
  const AccessControl* access;
  bool health_needs_token;
  RequestLog* log;

  // grpc_auth_metadata_processor::process. Runs on a gRPC thread for each new call; it does not
  // block, so it answers at once (the core allows calling `done` synchronously).
  static void Process(void* state, grpc_auth_context* /*context*/, const grpc_metadata* metadata,
                      size_t count, grpc_process_auth_metadata_done_cb done, void* user_data) {
    const auto* check = static_cast<const TokenCheck*>(state);
    absl::string_view method = "-";
    std::vector<absl::string_view> authorization;
    for (size_t i = 0; i < count; ++i) {
      const absl::string_view key = SliceView(metadata[i].key);
      if (key == ":path") method = SliceView(metadata[i].value);
      if (key == "authorization") authorization.push_back(SliceView(metadata[i].value));
    }
    // motiondb.v1's calls are checked in the service, where their peer is known; gRPC's own
    // services here (any valid token will do).
    if (IsMotionDbMethod(method) || !MethodNeedsToken(method, check->health_needs_token) ||
        check->access->ScopeOf(authorization).has_value()) {
      done(user_data, nullptr, 0, nullptr, 0, GRPC_STATUS_OK, nullptr);
      return;
    }
    // The call never reaches a service, so the request logger's interceptor does not see it.
    check->log->Record(kGrpcFace, method, grpc::StatusCode::UNAUTHENTICATED, 0.0, "");
    done(user_data, nullptr, 0, nullptr, 0, GRPC_STATUS_UNAUTHENTICATED,
         "missing or wrong bearer token: send the metadata 'authorization: Bearer <token>'");
  }

  static void Destroy(void* state) { delete static_cast<TokenCheck*>(state); }
};

// Credentials made at the C-core level (see the header for why). grpc::ServerCredentials keeps
// AddPortToServer private, but a derived class may still override it; grpc::Server calls it.
class CoreServerCredentials : public grpc::ServerCredentials {
 public:
  explicit CoreServerCredentials(grpc_server_credentials* credentials)
      : credentials_(credentials) {}
  ~CoreServerCredentials() override { grpc_server_credentials_release(credentials_); }

  void SetAuthMetadataProcessor(
      const std::shared_ptr<grpc::AuthMetadataProcessor>& /*processor*/) override {
    // Not used: the token check is attached in C (RequireBearerToken).
  }

  void RequireBearerToken(const AccessControl& access, bool health_needs_token, RequestLog& log) {
    grpc_auth_metadata_processor processor{};
    processor.process = &TokenCheck::Process;
    processor.destroy = &TokenCheck::Destroy;
    processor.state = new TokenCheck{&access, health_needs_token, &log};
    grpc_server_credentials_set_auth_metadata_processor(credentials_, processor);
  }

 private:
  int AddPortToServer(const std::string& address, grpc_server* server) override {
    return grpc_server_add_http2_port(server, address.c_str(), credentials_);
  }

  grpc_server_credentials* credentials_;
};

}  // namespace

bool MethodNeedsToken(absl::string_view method, bool health_needs_token) {
  return health_needs_token || !absl::StartsWith(method, "/grpc.health.v1.Health/");
}

bool BearerTokenMatches(absl::string_view header, absl::string_view token) {
  constexpr absl::string_view kScheme = "bearer ";
  if (header.size() < kScheme.size() ||
      !absl::EqualsIgnoreCase(header.substr(0, kScheme.size()), kScheme)) {
    return false;
  }
  if (token.empty()) return false;
  const absl::string_view given = header.substr(kScheme.size());
  // Compare every byte of the given value, against the token cycled when lengths differ, so the
  // time depends only on what the caller sent.
  unsigned char difference = given.size() == token.size() ? 0 : 1;
  for (size_t i = 0; i < given.size(); ++i) {
    difference |= static_cast<unsigned char>(given[i] ^ token[i % token.size()]);
  }
  return difference == 0;
}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const std::string& tls_cert_pem, const std::string& tls_key_pem, const AccessControl& access,
    bool health_needs_token, RequestLog& log) {
  if (tls_cert_pem.empty() != tls_key_pem.empty()) {
    return absl::InvalidArgumentError(
        "TLS needs both a certificate and a private key (--tls-cert and --tls-key)");
  }
  grpc_server_credentials* core = nullptr;
  if (tls_cert_pem.empty()) {
    core = grpc_insecure_server_credentials_create();
  } else {
    grpc_ssl_pem_key_cert_pair pair{tls_key_pem.c_str(), tls_cert_pem.c_str()};
    core = grpc_ssl_server_credentials_create_ex(
        /*pem_root_certs=*/nullptr, &pair, 1, GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE,
        /*reserved=*/nullptr);
    if (core == nullptr) {
      return absl::InvalidArgumentError("the TLS certificate or key is not valid PEM");
    }
  }
  auto credentials = std::make_shared<CoreServerCredentials>(core);
  if (access.enabled()) credentials->RequireBearerToken(access, health_needs_token, log);
  return credentials;
}

}  // namespace motiondb::server
