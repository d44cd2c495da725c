#include "server/edit/internal/request_fields.h"

#include <cctype>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"

namespace motiondb::server {
namespace {

// Field names are words of these characters: "warp.dims", "plane[2].x".
bool IsFieldCharacter(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '[' ||
         c == ']';
}

}  // namespace

absl::Status InRequestFields(const absl::Status& status, const RequestFields& fields) {
  if (status.ok()) return status;
  const absl::string_view message = status.message();
  size_t end = 0;
  while (end < message.size() && IsFieldCharacter(message[end])) ++end;
  const absl::string_view leading = message.substr(0, end);
  // A field is followed by its value or its complaint; "a clip named ..." is prose.
  const absl::string_view after = message.substr(end);
  if (!absl::StartsWith(after, ": ") && !absl::StartsWith(after, " = ")) return status;
  for (const auto& [parameter, field] : fields) {
    if (!absl::StartsWith(leading, parameter)) continue;
    if (leading.size() > parameter.size() && leading[parameter.size()] != '.' &&
        leading[parameter.size()] != '[') {
      continue;  // "b" is not the head of "before"
    }
    const absl::string_view rest = message.substr(parameter.size());
    absl::Status renamed(status.code(), absl::StrCat(field, rest));
    status.ForEachPayload([&renamed](absl::string_view type_url, const absl::Cord& payload) {
      renamed.SetPayload(type_url, payload);
    });
    return renamed;
  }
  return status;
}

absl::Status CheckDuration(absl::string_view field, double seconds, bool zero_allowed,
                           int max_frames, double rate) {
  // Compared as seconds x rate, so that no huge or non-finite value is ever converted to int.
  const bool above_zero = zero_allowed ? seconds >= 0.0 : seconds > 0.0;
  if (above_zero && seconds * rate <= max_frames) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(field, " = ", seconds, " is out of range; expected ",
                   zero_allowed ? "0 or more" : "more than 0", ", at most ", max_frames / rate,
                   " seconds (", max_frames, " frames at the space's ", rate, " fps)"));
}

}  // namespace motiondb::server
