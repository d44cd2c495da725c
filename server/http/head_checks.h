// What the HTTP face decides from a request's head alone, before its body is read: whether a
// body may come (only with a Content-Length, uncompressed, within the largest message, and to
// a route that takes one) and whether the caller holds the token. A body refused here is never
// read: a 300 MB POST without a token once took 1.95 GB before its refusal.
#ifndef MOTIONDB_SERVER_HTTP_HEAD_CHECKS_H_
#define MOTIONDB_SERVER_HTTP_HEAD_CHECKS_H_

#include <cstddef>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"
#include "server/http/connection_loop.h"
#include "server/http/request_head.h"
#include "util/token_file.h"

namespace motiondb::server {

// The paths of the routes that take a request body, as regular expressions.
std::vector<std::regex> BodyRoutePaths();

// A refusal of the request's body, or nullopt: httplib 0.11 would read a chunked body and
// inflate a compressed one whole before any handler ran, and read a POST without a length until
// the connection ended.
std::optional<HttpRefusal> RefuseBody(const RequestHead& head, size_t max_body,
                                      const std::vector<std::regex>& body_routes);

// Whether `path` is the JSON API's.
bool IsApiPath(absl::string_view path);

// The scope a request needs (util/token_file.h), or nullopt when it needs no token: the API's
// routes as their gRPC methods (server/grpc/method_scopes.h), an unknown API path read (a 404
// for whoever holds a token), /metrics admin, /healthz and /readyz as the gRPC health service
// (`health_needs_token`), the web UI's files never (they hold no data).
std::optional<TokenScope> NeededScope(absl::string_view method, absl::string_view path,
                                      bool health_needs_token);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_HEAD_CHECKS_H_
