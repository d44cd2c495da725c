#include "util/name_text.h"

#include <cstdint>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace motiondb {
namespace {

// One character at the start of `text`: its code point and length, or, for an ill-formed
// sequence, no code point and the length of its longest start of a well-formed sequence (at
// least 1), which is what one U+FFFD replaces (Unicode's "maximal subpart" practice).
struct Decoded {
  std::optional<char32_t> code_point;
  size_t length = 1;
};

Decoded DecodeUtf8(absl::string_view text) {
  const auto byte = [&text](size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return {lead, 1};
  size_t length = 0;
  char32_t code_point = 0;
  // The range the second byte must fall in: narrower than 0x80-0xBF after E0, ED, F0 and F4, to
  // refuse overlong forms, surrogates and code points past U+10FFFF.
  unsigned char low = 0x80, high = 0xBF;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
    code_point = lead & 0x1F;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    code_point = lead & 0x0F;
    if (lead == 0xE0) low = 0xA0;
    if (lead == 0xED) high = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    code_point = lead & 0x07;
    if (lead == 0xF0) low = 0x90;
    if (lead == 0xF4) high = 0x8F;
  } else {
    return {std::nullopt, 1};
  }
  for (size_t i = 1; i < length; ++i) {
    const bool fits =
        i < text.size() && byte(i) >= (i == 1 ? low : 0x80) && byte(i) <= (i == 1 ? high : 0xBF);
    if (!fits) return {std::nullopt, i};
    code_point = (code_point << 6) | (byte(i) & 0x3F);
  }
  return {code_point, length};
}

// What the rule says of a code point, or "" when it passes.
std::string Refusal(char32_t c) {
  if (c < 0x20 || (c >= 0x7F && c <= 0x9F)) return "a control character";
  if (c == 0x061C || c == 0x200E || c == 0x200F || (c >= 0x202A && c <= 0x202E) ||
      (c >= 0x2066 && c <= 0x2069)) {
    return absl::StrFormat("the bidirectional control U+%04X", static_cast<uint32_t>(c));
  }
  if (c == 0x2028) return "the line separator U+2028";
  if (c == 0x2029) return "the paragraph separator U+2029";
  return "";
}

}  // namespace

std::optional<NameTextProblem> FindNameTextProblem(absl::string_view text) {
  for (size_t at = 0; at < text.size();) {
    const Decoded decoded = DecodeUtf8(text.substr(at));
    if (!decoded.code_point) return NameTextProblem{at, "invalid UTF-8"};
    if (std::string refused = Refusal(*decoded.code_point); !refused.empty()) {
      return NameTextProblem{at, std::move(refused)};
    }
    at += decoded.length;
  }
  return std::nullopt;
}

absl::Status CheckNameText(absl::string_view what, absl::string_view text) {
  const std::optional<NameTextProblem> problem = FindNameTextProblem(text);
  if (!problem) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(what, " ", QuotedNameText(text), " holds ",
                                                 problem->what, " at byte ", problem->byte,
                                                 "; names are printable UTF-8 text"));
}

std::string QuotedNameText(absl::string_view text) {
  constexpr size_t kShown = 80;
  std::string quoted = "'";
  size_t at = 0;
  for (; at < text.size() && at < kShown;) {
    const Decoded decoded = DecodeUtf8(text.substr(at));
    if (!decoded.code_point) {
      for (size_t i = 0; i < decoded.length; ++i) {
        absl::StrAppend(&quoted, absl::StrFormat("\\x%02x", static_cast<uint8_t>(text[at + i])));
      }
    } else if (const char32_t c = *decoded.code_point; c == '\\') {
      quoted += "\\\\";
    } else if (c == '\t' || c == '\n' || c == '\r') {
      quoted += c == '\t' ? "\\t" : c == '\n' ? "\\n" : "\\r";
    } else if (Refusal(c).empty()) {
      quoted.append(text.data() + at, decoded.length);
    } else if (c < 0x80) {
      absl::StrAppend(&quoted, absl::StrFormat("\\x%02x", static_cast<uint32_t>(c)));
    } else {
      absl::StrAppend(&quoted, absl::StrFormat("\\u%04X", static_cast<uint32_t>(c)));
    }
    at += decoded.length;
  }
  return absl::StrCat(quoted, at < text.size() ? "...'" : "'");
}

std::string ValidUtf8(absl::string_view text) {
  std::string valid;
  size_t copied = 0;  // text before this is in `valid` already
  for (size_t at = 0; at < text.size();) {
    const Decoded decoded = DecodeUtf8(text.substr(at));
    if (!decoded.code_point) {
      valid.append(text.data() + copied, at - copied);
      valid.append("\xEF\xBF\xBD");  // U+FFFD
      copied = at + decoded.length;
    }
    at += decoded.length;
  }
  if (copied == 0) return std::string(text);
  valid.append(text.data() + copied, text.size() - copied);
  return valid;
}

}  // namespace motiondb
