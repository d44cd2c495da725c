#include "util/token_file.h"

#include <cstdint>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// A token is small; anything larger is a wrong path.
constexpr int64_t kMaxTokenFileBytes = int64_t{1} << 20;

// It travels in an HTTP/2 header value.
bool Printable(absl::string_view token) {
  for (const char c : token) {
    if (!absl::ascii_isgraph(static_cast<unsigned char>(c))) return false;
  }
  return !token.empty();
}

}  // namespace

absl::StatusOr<std::string> ReadTokenFile(const std::string& path) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, ReadFileBytes(path, kMaxTokenFileBytes));
  const std::string token(absl::StripAsciiWhitespace(text));
  if (token.empty()) return absl::InvalidArgumentError(absl::StrCat(path, ": the token is empty"));
  if (!Printable(token)) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": the token must be printable ASCII without spaces"));
  }
  return token;
}

absl::string_view TokenScopeName(TokenScope scope) {
  switch (scope) {
    case TokenScope::kRead:
      return "read";
    case TokenScope::kWrite:
      return "write";
    case TokenScope::kAdmin:
      return "admin";
    case TokenScope::kCluster:
      return "cluster";
  }
  return "admin";
}

absl::StatusOr<std::vector<ScopedToken>> ReadScopedTokenFile(const std::string& path) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, ReadFileBytes(path, kMaxTokenFileBytes));
  std::vector<ScopedToken> tokens;
  absl::flat_hash_set<std::string> seen;
  bool bare = false;
  int number = 0;
  for (const absl::string_view raw : absl::StrSplit(text, '\n')) {
    ++number;
    const absl::string_view line = absl::StripAsciiWhitespace(raw);
    if (line.empty() || line[0] == '#') continue;
    const auto at = [&path, number](absl::string_view what) {
      return absl::InvalidArgumentError(absl::StrCat(path, ": line ", number, ": ", what));
    };
    const std::vector<absl::string_view> words = absl::StrSplit(line, ' ', absl::SkipWhitespace());
    ScopedToken token;
    if (words.size() == 1) {
      bare = true;
      token.token = std::string(words[0]);
    } else if (words.size() == 2) {
      if (words[0] == "read") {
        token.scope = TokenScope::kRead;
      } else if (words[0] == "write") {
        token.scope = TokenScope::kWrite;
      } else if (words[0] == "admin") {
        token.scope = TokenScope::kAdmin;
      } else {
        return at(absl::StrCat("unknown scope '", words[0], "' (read, write or admin)"));
      }
      token.token = std::string(words[1]);
    } else {
      return at("expected 'SCOPE TOKEN' (read, write or admin, then the token)");
    }
    if (!Printable(token.token)) return at("the token must be printable ASCII without spaces");
    if (!seen.insert(token.token).second) return at("this token is given twice");
    tokens.push_back(std::move(token));
  }
  if (tokens.empty()) return absl::InvalidArgumentError(absl::StrCat(path, ": no token"));
  if (bare && tokens.size() > 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        path,
        ": a token without a scope is allowed only alone (a file of one bare token); give "
        "each line its scope: 'read TOKEN', 'write TOKEN' or 'admin TOKEN'"));
  }
  return tokens;
}

}  // namespace motiondb
