// What the HTTP face checks of a request before its route runs, so that a page of another web
// site, open in a browser beside the web UI, can neither change nor read the database through
// the browser (docs/server-limits.md, "Cross-origin requests"):
//   - The Host header must be an IP address, localhost, or a name --http-allowed-hosts lists
//     ("*": any), else 421: a page whose own name was rebound to this server's address (DNS
//     rebinding) sends that name, while a page loaded from an address or from localhost is
//     that server's own. Its port is not checked: a container's or a proxy's port mapping
//     changes it, and the name is what tells a rebound page. /healthz and /readyz answer
//     whatever the Host, for probes that name the host otherwise, and so does a request
//     without one, which no browser sends.
//   - A POST to the API must say Content-Type: application/json (a charset parameter, if any,
//     utf-8). Else 415: a page may send text/plain, a form or nothing without the browser asking
//     first, but application/json only after a CORS preflight, which a page of another origin
//     fails unless --http-cors-origins lists it.
//   - CORS is off by default (no Access-Control-* header is ever sent); --http-cors-origins
//     names the origins whose pages may call the API: their preflight (OPTIONS) is answered 204
//     without a token, any other origin's refused (403), and their answers carry
//     Access-Control-Allow-Origin.
//   - A path holding a control character once percent-decoded (%00, %0A) is refused (400): a
//     file's name would be cut at the NUL while its type was read from what followed.
//
// The checks run twice, after the token's and the body's: on the head the connection loop reads
// before any body (server/http/request_head.h), so that a refused body is never read, and on
// cpp-httplib's own parse of the whole request, which answers the preflights and adds the CORS
// headers.
//
// Immutable once created; thread-safe.
#ifndef MOTIONDB_SERVER_HTTP_REQUEST_CHECKS_H_
#define MOTIONDB_SERVER_HTTP_REQUEST_CHECKS_H_

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "server/http/connection_loop.h"
#include "server/http/request_head.h"

namespace httplib {
struct Request;
}  // namespace httplib

namespace motiondb::server {

// What the checks read of a request, from either parse of it.
struct RequestFacts {
  std::string method;
  std::string path;  // percent-decoded
  std::optional<std::string> host, content_type, origin;
  bool preflight = false;  // OPTIONS with Access-Control-Request-Method

  static RequestFacts Of(const RequestHead& head);
  static RequestFacts Of(const httplib::Request& request);
};

class RequestChecks {
 public:
  // `allowed_hosts`: host names (or addresses, an IPv6 one in brackets) without a port, or "*"
  // alone. `cors_origins`: http:// or https:// origins,
  // scheme://host[:port] without a path. INVALID_ARGUMENT naming the flag for a malformed entry.
  static absl::StatusOr<RequestChecks> Create(const std::vector<std::string>& allowed_hosts,
                                              const std::vector<std::string>& cors_origins);

  // A refusal of the request (carrying the CORS headers of a listed origin, so that its page
  // can read why), or nullopt.
  std::optional<HttpRefusal> Refuse(const RequestFacts& request) const;
  // Whether the request is the preflight of a listed origin: answered 204 with CorsHeaders,
  // without a token (a browser sends none with it).
  bool ListedPreflight(const RequestFacts& request) const;
  // The CORS headers of an answer to the request: none unless its origin is listed.
  std::vector<std::pair<std::string, std::string>> CorsHeaders(const RequestFacts& request) const;

 private:
  RequestChecks() = default;

  bool HostAllowed(const RequestFacts& request) const;
  bool Listed(const RequestFacts& request) const;

  bool any_host_ = false;
  std::vector<std::string> hosts_;    // lowercase, an IPv6 address without brackets
  std::vector<std::string> origins_;  // lowercase
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_REQUEST_CHECKS_H_
