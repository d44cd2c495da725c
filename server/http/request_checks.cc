#include "server/http/request_checks.h"

#include <arpa/inet.h>

#include <algorithm>

#include <httplib.h>

#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace motiondb::server {
namespace {

constexpr char kHostsFlag[] = "--http-allowed-hosts";
constexpr char kOriginsFlag[] = "--http-cors-origins";

// A host and its port as a Host header or a flag gives them.
struct HostPort {
  std::string name;  // lowercase; an IPv6 address without its brackets
  std::optional<int> port;
};

// "name", "name:8080", "10.0.0.5:8080", "[::1]:8080", "[::1]"; nullopt when malformed (a bare
// IPv6 address, an empty name, a port that is not 1..65535).
std::optional<HostPort> ParseHostPort(absl::string_view text) {
  HostPort parsed;
  absl::string_view rest;
  if (absl::ConsumePrefix(&text, "[")) {
    const size_t close = text.find(']');
    if (close == absl::string_view::npos) return std::nullopt;
    parsed.name = std::string(text.substr(0, close));
    rest = text.substr(close + 1);
  } else {
    const size_t colon = text.find(':');
    if (colon != absl::string_view::npos && text.find(':', colon + 1) != absl::string_view::npos) {
      return std::nullopt;
    }
    parsed.name = std::string(text.substr(0, colon));
    if (colon != absl::string_view::npos) rest = text.substr(colon);
  }
  if (parsed.name.empty() || std::any_of(parsed.name.begin(), parsed.name.end(), [](char c) {
        return !(absl::ascii_isalnum(c) || c == '.' || c == '-' || c == '_' || c == ':' ||
                 c == '%');
      })) {
    return std::nullopt;
  }
  absl::AsciiStrToLower(&parsed.name);
  if (!rest.empty()) {
    int port = 0;
    if (!absl::ConsumePrefix(&rest, ":") || rest.empty() ||
        !std::all_of(rest.begin(), rest.end(), absl::ascii_isdigit) ||
        !absl::SimpleAtoi(rest, &port) || port < 1 || port > 65535) {
      return std::nullopt;
    }
    parsed.port = port;
  }
  return parsed;
}

// Whether `text` is an IPv4 or IPv6 address (with a scope or not, "fe80::1%eth0").
bool IsIpAddress(absl::string_view text) {
  const std::string address(text.substr(0, text.find('%')));
  unsigned char bytes[16];
  return inet_pton(AF_INET, address.c_str(), bytes) == 1 ||
         inet_pton(AF_INET6, address.c_str(), bytes) == 1;
}

// The origins of --http-cors-origins: "http://host[:port]" or "https://...", nothing after.
bool IsOrigin(absl::string_view origin) {
  return (absl::ConsumePrefix(&origin, "http://") || absl::ConsumePrefix(&origin, "https://")) &&
         ParseHostPort(origin).has_value();
}

// `text` for an error message: escaped and shortened.
std::string Shown(absl::string_view text) {
  constexpr size_t kShown = 100;
  return absl::StrCat("'", absl::CHexEscape(text.substr(0, kShown)),
                      text.size() > kShown ? "...'" : "'");
}

// Why a POST's Content-Type is not JSON's, or "" when it is: application/json with no charset
// or charset=utf-8 (any case, quoted or not).
std::string NotJson(const std::optional<std::string>& type) {
  if (!type) return "it has none";
  const std::vector<absl::string_view> parts = absl::StrSplit(*type, ';');
  if (!absl::EqualsIgnoreCase(absl::StripAsciiWhitespace(parts[0]), "application/json")) {
    return absl::StrCat("it is ", Shown(*type));
  }
  for (size_t i = 1; i < parts.size(); ++i) {
    const std::pair<absl::string_view, absl::string_view> parameter =
        absl::StrSplit(parts[i], absl::MaxSplits('=', 1));
    absl::string_view value = absl::StripAsciiWhitespace(parameter.second);
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') {
      value = value.substr(1, value.size() - 2);
    }
    if (absl::EqualsIgnoreCase(absl::StripAsciiWhitespace(parameter.first), "charset") &&
        !absl::EqualsIgnoreCase(value, "utf-8")) {
      return absl::StrCat("its charset is ", Shown(value), ", and JSON is UTF-8");
    }
  }
  return "";
}

// The first value of a head's field `name` (lower case), if any.
std::optional<std::string> FirstValue(const RequestHead& head, absl::string_view name) {
  const std::vector<absl::string_view> values = head.Values(name);
  if (values.empty()) return std::nullopt;
  return std::string(values.front());
}

std::optional<std::string> FirstValue(const httplib::Request& request, const char* name) {
  if (!request.has_header(name)) return std::nullopt;
  return request.get_header_value(name);
}

}  // namespace

RequestFacts RequestFacts::Of(const RequestHead& head) {
  RequestFacts facts{head.method, head.path, FirstValue(head, "host"),
                     FirstValue(head, "content-type"), FirstValue(head, "origin")};
  facts.preflight = head.method == "OPTIONS" && head.Has("access-control-request-method");
  return facts;
}

RequestFacts RequestFacts::Of(const httplib::Request& request) {
  RequestFacts facts{request.method, request.path, FirstValue(request, "Host"),
                     FirstValue(request, "Content-Type"), FirstValue(request, "Origin")};
  facts.preflight =
      request.method == "OPTIONS" && request.has_header("Access-Control-Request-Method");
  return facts;
}

absl::StatusOr<RequestChecks> RequestChecks::Create(const std::vector<std::string>& allowed_hosts,
                                                    const std::vector<std::string>& cors_origins) {
  RequestChecks checks;
  for (const std::string& entry : allowed_hosts) {
    const absl::string_view host = absl::StripAsciiWhitespace(entry);
    if (host == "*") {
      checks.any_host_ = true;
      continue;
    }
    const std::optional<HostPort> parsed = ParseHostPort(host);
    if (!parsed || parsed->port) {
      return absl::InvalidArgumentError(absl::StrCat(
          kHostsFlag, ": ", Shown(host),
          " is not a host name or address (an IPv6 address in brackets; no port: the Host's "
          "port is not checked), or *"));
    }
    checks.hosts_.push_back(parsed->name);
  }
  for (const std::string& entry : cors_origins) {
    const std::string origin = absl::AsciiStrToLower(absl::StripAsciiWhitespace(entry));
    if (!IsOrigin(origin)) {
      return absl::InvalidArgumentError(
          absl::StrCat(kOriginsFlag, ": ", Shown(origin),
                       " is not an origin such as https://studio.example or "
                       "http://127.0.0.1:5173 (scheme, host and port, no path; no *)"));
    }
    checks.origins_.push_back(origin);
  }
  return checks;
}

bool RequestChecks::HostAllowed(const RequestFacts& request) const {
  // No browser leaves Host out: a request without one is no page's.
  if (any_host_ || !request.host) return true;
  const std::optional<HostPort> host = ParseHostPort(*request.host);
  if (!host) return false;
  // A page sends the name it was loaded from: an address or localhost is that of a page
  // served from there, never one of a rebound name. The port is left alone: a container's or
  // a proxy's mapping changes it.
  return host->name == "localhost" || IsIpAddress(host->name) ||
         std::find(hosts_.begin(), hosts_.end(), host->name) != hosts_.end();
}

bool RequestChecks::Listed(const RequestFacts& request) const {
  return request.origin && std::find(origins_.begin(), origins_.end(),
                                     absl::AsciiStrToLower(*request.origin)) != origins_.end();
}

std::optional<HttpRefusal> RequestChecks::Refuse(const RequestFacts& request) const {
  if (const auto control =
          std::find_if(request.path.begin(), request.path.end(),
                       [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7F; });
      control != request.path.end()) {
    return HttpRefusal(400, absl::StrCat("the path holds a control character (byte ",
                                         control - request.path.begin(), " once percent-decoded)"));
  }
  const bool health = request.path == "/healthz" || request.path == "/readyz";
  if (!health && !HostAllowed(request)) {
    return HttpRefusal(
        421, absl::StrCat("the Host header ", Shown(*request.host),
                          " does not name this server: it answers to IP addresses and "
                          "localhost, and to the names ",
                          kHostsFlag,
                          " lists (a page on a name rebound to this address would read it "
                          "otherwise)"));
  }
  if (request.preflight && request.origin && !Listed(request)) {
    return HttpRefusal(
        403, absl::StrCat("pages of ", Shown(*request.origin), " may not call this server (",
                          kOriginsFlag, " lists the origins that may; none by default)"));
  }
  const bool api = request.path == "/v1" || absl::StartsWith(request.path, "/v1/");
  if (request.method == "POST" && api) {
    if (const std::string why = NotJson(request.content_type); !why.empty()) {
      return HttpRefusal(
          415, absl::StrCat("POST ", request.path,
                            " takes a JSON body sent with 'Content-Type: application/json', but ",
                            why, " (curl: -H 'Content-Type: application/json')"));
    }
  }
  return std::nullopt;
}

bool RequestChecks::ListedPreflight(const RequestFacts& request) const {
  return request.preflight && Listed(request);
}

std::vector<std::pair<std::string, std::string>> RequestChecks::CorsHeaders(
    const RequestFacts& request) const {
  if (!Listed(request)) return {};
  std::vector<std::pair<std::string, std::string>> headers = {
      {"Access-Control-Allow-Origin", *request.origin}, {"Vary", "Origin"}};
  if (request.preflight) {
    headers.insert(headers.end(), {{"Access-Control-Allow-Methods", "GET, POST, DELETE"},
                                   {"Access-Control-Allow-Headers", "Authorization, Content-Type"},
                                   {"Access-Control-Max-Age", "600"}});
  } else {
    headers.emplace_back("Access-Control-Expose-Headers", "Content-Disposition");
  }
  return headers;
}

}  // namespace motiondb::server
