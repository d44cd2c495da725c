#include "server/http/request_head.h"

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace motiondb::server {
namespace {

// The end of the head (past its blank line), or npos.
size_t HeadEnd(absl::string_view buffer) {
  for (size_t newline = buffer.find('\n'); newline != absl::string_view::npos;
       newline = buffer.find('\n', newline + 1)) {
    const absl::string_view after = buffer.substr(newline + 1);
    if (absl::StartsWith(after, "\n")) return newline + 2;
    if (absl::StartsWith(after, "\r\n")) return newline + 3;
  }
  return absl::string_view::npos;
}

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  c = absl::ascii_tolower(c);
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// The path of `target` percent-decoded, as cpp-httplib decodes it for routing ('+' stays).
std::string DecodedPath(absl::string_view target) {
  const absl::string_view path = target.substr(0, target.find('?'));
  std::string decoded;
  for (size_t i = 0; i < path.size(); ++i) {
    if (path[i] == '%' && i + 2 < path.size() && HexValue(path[i + 1]) >= 0 &&
        HexValue(path[i + 2]) >= 0) {
      decoded += static_cast<char>(HexValue(path[i + 1]) * 16 + HexValue(path[i + 2]));
      i += 2;
    } else {
      decoded += path[i];
    }
  }
  return decoded;
}

bool IsToken(absl::string_view name) {
  if (name.empty()) return false;
  for (const char c : name) {
    if (absl::ascii_isspace(c) || absl::ascii_iscntrl(c) || c == ':') return false;
  }
  return true;
}

}  // namespace

std::vector<absl::string_view> RequestHead::Values(absl::string_view name) const {
  std::vector<absl::string_view> values;
  for (const auto& [field, value] : fields) {
    if (field == name) values.push_back(value);
  }
  return values;
}

HeadParse ParseRequestHead(absl::string_view buffer, RequestHead* head) {
  const size_t end = HeadEnd(buffer);
  if (end == absl::string_view::npos) {
    return buffer.size() > kMaxRequestHeadBytes ? HeadParse::kTooLarge : HeadParse::kIncomplete;
  }
  if (end > kMaxRequestHeadBytes) return HeadParse::kTooLarge;
  *head = RequestHead{};
  head->bytes = end;
  std::vector<absl::string_view> lines = absl::StrSplit(buffer.substr(0, end), '\n');
  lines.resize(lines.size() - 2);  // the blank line and what follows its newline
  if (lines.empty()) return HeadParse::kMalformed;
  if (static_cast<int>(lines.size()) - 1 > kMaxRequestFields) return HeadParse::kTooLarge;
  const std::vector<absl::string_view> request_line =
      absl::StrSplit(absl::StripSuffix(lines[0], "\r"), ' ');
  if (request_line.size() != 3 || request_line[0].empty() || request_line[1].empty() ||
      !absl::StartsWith(request_line[2], "HTTP/1.")) {
    return HeadParse::kMalformed;
  }
  head->method = std::string(request_line[0]);
  head->target = std::string(request_line[1]);
  head->path = DecodedPath(head->target);
  head->version = std::string(request_line[2]);
  for (size_t i = 1; i < lines.size(); ++i) {
    const absl::string_view line = absl::StripSuffix(lines[i], "\r");
    const size_t colon = line.find(':');
    if (colon == absl::string_view::npos || !IsToken(line.substr(0, colon))) {
      return HeadParse::kMalformed;
    }
    head->fields.emplace_back(absl::AsciiStrToLower(line.substr(0, colon)),
                              std::string(absl::StripAsciiWhitespace(line.substr(colon + 1))));
  }
  return HeadParse::kComplete;
}

std::optional<size_t> ContentLength(const RequestHead& head, std::string* problem) {
  std::optional<size_t> length;
  for (const absl::string_view value : head.Values("content-length")) {
    size_t parsed = 0;
    if (value.empty() || !absl::ascii_isdigit(value[0]) || !absl::SimpleAtoi(value, &parsed)) {
      *problem = "the Content-Length is not a number";
      return std::nullopt;
    }
    if (length && *length != parsed) {
      *problem = "the request has several Content-Lengths that differ";
      return std::nullopt;
    }
    length = parsed;
  }
  return length.value_or(0);
}

std::string WithoutExpect(absl::string_view head_bytes) {
  std::string kept;
  kept.reserve(head_bytes.size());
  for (absl::string_view rest = head_bytes; !rest.empty();) {
    const size_t newline = rest.find('\n');
    const absl::string_view line =
        newline == absl::string_view::npos ? rest : rest.substr(0, newline + 1);
    rest.remove_prefix(line.size());
    if (!absl::StartsWithIgnoreCase(line, "expect:")) kept.append(line.data(), line.size());
  }
  return kept;
}

}  // namespace motiondb::server
