#include "util/token_file.h"

#include <cstdint>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// A token is small; anything larger is a wrong path.
constexpr int64_t kMaxTokenFileBytes = int64_t{1} << 20;

}  // namespace

absl::StatusOr<std::string> ReadTokenFile(const std::string& path) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, ReadFileBytes(path, kMaxTokenFileBytes));
  const std::string token(absl::StripAsciiWhitespace(text));
  if (token.empty()) return absl::InvalidArgumentError(absl::StrCat(path, ": the token is empty"));
  for (const char c : token) {
    if (!absl::ascii_isgraph(static_cast<unsigned char>(c))) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": the token must be printable ASCII without spaces"));
    }
  }
  return token;
}

}  // namespace motiondb
