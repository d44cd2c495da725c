// An HTTP/1.1 request's head (request line and header fields) read before anything else of the
// request is: how much body follows, whether it needs a 100 Continue, what the checks that
// come before the body (server/http/request_gate.h) look at. cpp-httplib parses the whole
// request again once it is complete; this reads only what decides whether and how to read on.
#ifndef MOTIONDB_SERVER_HTTP_REQUEST_HEAD_H_
#define MOTIONDB_SERVER_HTTP_REQUEST_HEAD_H_

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/string_view.h"

namespace motiondb::server {

// The most a head may hold: request line and fields together, and fields. Browsers send 1-3 KiB
// (a page's cookies included); 200 MB of headers once took the server's memory 66 -> 362 MB.
inline constexpr size_t kMaxRequestHeadBytes = 64 << 10;
inline constexpr int kMaxRequestFields = 100;

struct RequestHead {
  std::string method;
  std::string target;   // as sent: path and query, percent-encoded
  std::string path;     // the target's path, percent-decoded
  std::string version;  // "HTTP/1.1"
  std::vector<std::pair<std::string, std::string>> fields;  // names lower-cased, values trimmed
  size_t bytes = 0;  // the head's length, its blank line included

  // Every value of the field `name` (lower case).
  std::vector<absl::string_view> Values(absl::string_view name) const;
  bool Has(absl::string_view name) const { return !Values(name).empty(); }
};

enum class HeadParse {
  kIncomplete,  // no blank line yet, within the limits
  kComplete,
  kTooLarge,   // 431: over kMaxRequestHeadBytes or kMaxRequestFields
  kMalformed,  // 400
};

// Parses the head at the start of `buffer` (the connection's bytes so far) into `head` once its
// blank line has arrived. Lines end in CRLF or LF, as RFC 9112 lets a server accept; a field
// line without a colon, or a name with a space, is malformed (request smuggling).
HeadParse ParseRequestHead(absl::string_view buffer, RequestHead* head);

// The body's length: 0 without a Content-Length (GET), the number when there is one; nullopt,
// with `problem` set, for several differing lengths or one that is no number.
std::optional<size_t> ContentLength(const RequestHead& head, std::string* problem);

// `head`'s bytes without the Expect field's line: the server answers "100 Continue" itself once
// it has decided to read the body, and cpp-httplib must not answer it again.
std::string WithoutExpect(absl::string_view head_bytes);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_REQUEST_HEAD_H_
