#include "cluster/node_address.h"

#include <unistd.h>

#include <array>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace motiondb::cluster {
namespace {

struct HostPort {
  absl::string_view host;  // an IPv6 literal keeps its brackets
  absl::string_view port;  // empty when none was given
};

// "host", "host:port", "[v6]" or "[v6]:port"; a bare IPv6 literal ("fd00::1") is a host.
HostPort SplitHostPort(absl::string_view text) {
  if (absl::StartsWith(text, "[")) {
    const size_t close = text.find(']');
    if (close == absl::string_view::npos) return {text, ""};
    const absl::string_view rest = text.substr(close + 1);
    return {text.substr(0, close + 1), absl::StartsWith(rest, ":") ? rest.substr(1) : rest};
  }
  const size_t colon = text.find(':');
  if (colon == absl::string_view::npos || text.find(':', colon + 1) != absl::string_view::npos) {
    return {text, ""};
  }
  return {text.substr(0, colon), text.substr(colon + 1)};
}

bool IsWildcard(absl::string_view host) {
  return host.empty() || host == "0.0.0.0" || host == "[::]" || host == "::" || host == "*";
}

}  // namespace

absl::StatusOr<std::string> AdvertisedAddress(absl::string_view advertise, absl::string_view listen,
                                              int port, absl::string_view host_name) {
  if (advertise.empty()) {
    absl::string_view host = SplitHostPort(listen).host;
    if (IsWildcard(host)) host = host_name;
    return absl::StrCat(host, ":", port);
  }
  const HostPort given = SplitHostPort(advertise);
  const auto bad = [&](absl::string_view why) {
    return absl::InvalidArgumentError(
        absl::StrCat("--advertise '", advertise, "': ", why,
                     "; expected HOST or HOST:PORT that other nodes reach this one at"));
  };
  if (IsWildcard(given.host)) return bad("a wildcard host reaches no node");
  if (absl::StartsWith(given.host, "[") != absl::EndsWith(given.host, "]")) {
    return bad("an IPv6 host's brackets do not close");
  }
  for (const char c : given.host) {
    if (absl::ascii_isspace(static_cast<unsigned char>(c)) || c == '/') {
      return bad("the host holds a space or '/'");
    }
  }
  if (given.host.find(':') != absl::string_view::npos && !absl::StartsWith(given.host, "[")) {
    return absl::StrCat("[", given.host, "]:", port);  // a bare IPv6 literal
  }
  if (given.port.empty()) return absl::StrCat(given.host, ":", port);
  int advertised_port = 0;
  if (!absl::SimpleAtoi(given.port, &advertised_port) || advertised_port < 1 ||
      advertised_port > 65535) {
    return bad("the port is not 1-65535");
  }
  return absl::StrCat(given.host, ":", advertised_port);
}

std::string MachineHostName() {
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) != 0 || name[0] == '\0') return "localhost";
  return name.data();
}

}  // namespace motiondb::cluster
