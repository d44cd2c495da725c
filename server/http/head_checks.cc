#include "server/http/head_checks.h"

#include <algorithm>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/grpc/credentials.h"
#include "server/grpc/method_scopes.h"
#include "server/http/api_routes.h"

namespace motiondb::server {

std::vector<std::regex> BodyRoutePaths() {
  std::vector<std::regex> paths;
  for (const ApiRoute& route : ApiRoutes()) {
    if (route.json_body) paths.emplace_back(route.PathRegex());
  }
  return paths;
}

std::optional<HttpRefusal> RefuseBody(const RequestHead& head, size_t max_body,
                                      const std::vector<std::regex>& body_routes) {
  if (head.Has("transfer-encoding")) {
    return HttpRefusal{411, "send the request body with a Content-Length, not a Transfer-Encoding"};
  }
  if (head.Has("content-encoding")) {
    return HttpRefusal{415, "send the request body uncompressed, without a Content-Encoding"};
  }
  if (!head.Has("content-length")) {
    if (head.method != "POST") return std::nullopt;
    return HttpRefusal{411, "a POST needs a Content-Length (curl: -d '' for an empty body)"};
  }
  std::string problem;
  const size_t length = ContentLength(head, &problem).value_or(0);  // parsed by the loop already
  const bool takes_body =
      head.method == "POST" &&
      std::any_of(body_routes.begin(), body_routes.end(),
                  [&head](const std::regex& path) { return std::regex_match(head.path, path); });
  if (length > 0 && !takes_body) {
    return HttpRefusal{413, absl::StrCat(head.method, " ", head.path, " takes no request body")};
  }
  if (length > max_body) {
    return HttpRefusal{413,
                       absl::StrCat("the request body is larger than the ", max_body,
                                    " bytes the server takes (--max-message-mb, base64-encoded)")};
  }
  return std::nullopt;
}

bool IsApiPath(absl::string_view path) { return path == "/v1" || absl::StartsWith(path, "/v1/"); }

namespace {

struct RouteScope {
  std::string http_method;
  std::regex path;
  TokenScope scope;
};

const std::vector<RouteScope>& RouteScopes() {
  static const auto* const scopes = [] {
    auto* table = new std::vector<RouteScope>();
    for (const ApiRoute& route : ApiRoutes()) {
      // "motiondb.v1.ClipService.ListClips" is the gRPC method
      // "/motiondb.v1.ClipService/ListClips".
      std::string method = absl::StrCat("/", route.rpc);
      method[method.rfind('.')] = '/';
      table->push_back({route.http_method, std::regex(route.PathRegex()), RequiredScope(method)});
    }
    return table;
  }();
  return *scopes;
}

}  // namespace

std::optional<TokenScope> NeededScope(absl::string_view method, absl::string_view path,
                                      bool health_needs_token) {
  if (path == "/healthz" || path == "/readyz") {
    if (!MethodNeedsToken("/grpc.health.v1.Health/Check", health_needs_token)) return std::nullopt;
    return TokenScope::kRead;
  }
  if (path == "/metrics") return TokenScope::kAdmin;
  if (!IsApiPath(path)) return std::nullopt;
  const absl::string_view routed = method == "HEAD" ? "GET" : method;
  const std::string path_text(path);
  for (const RouteScope& route : RouteScopes()) {
    if (route.http_method == routed && std::regex_match(path_text, route.path)) return route.scope;
  }
  return TokenScope::kRead;
}

}  // namespace motiondb::server
