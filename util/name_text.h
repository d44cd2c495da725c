// The rule for text that names things (clip, joint, space and pose model names, tags, label
// descriptors): where such text enters the server it is checked here, and what older versions
// stored without the check is answered through ValidUtf8. docs/server-limits.md ("Text") states
// the rule for users.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_UTIL_NAME_TEXT_H_
#define MOTIONDB_UTIL_NAME_TEXT_H_

#include <cstddef>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace motiondb {

// The first thing in a name that the rule refuses: where (a byte offset) and what ("invalid
// UTF-8", "a control character", "the bidirectional control U+202E", "the line separator
// U+2028").
struct NameTextProblem {
  size_t byte = 0;
  std::string what;
};

// A name must be well-formed UTF-8 (no overlong forms, surrogates or code points past U+10FFFF)
// and hold no character that hides, rewrites or reorders the text printed around it in a
// listing, a log line, a terminal or a spreadsheet:
//   - control characters: C0 (NUL included), DEL and C1 (U+0080-U+009F);
//   - the Unicode Bidi_Control characters: U+061C, U+200E, U+200F (the marks, invisible: two
//     names could differ by them alone), U+202A-U+202E (embeddings, overrides) and U+2066-U+2069
//     (isolates);
//   - the line and paragraph separators U+2028 and U+2029.
// Other invisible characters (U+200B, U+FEFF) pass: they neither reorder nor break a line.
std::optional<NameTextProblem> FindNameTextProblem(absl::string_view text);

// OK, or INVALID_ARGUMENT "`what` 'TEXT' holds PROBLEM at byte N; names are printable UTF-8
// text", TEXT as QuotedNameText shows it.
absl::Status CheckNameText(absl::string_view what, absl::string_view text);

// `text` quoted for a message, which must not itself hold what the rule refuses: its first 80
// bytes or so (whole characters), then "..." if there is more, between apostrophes; a
// backslash, tab, line feed and carriage return as \\, \t, \n and \r, other control
// characters and bytes of ill-formed UTF-8 as \xhh, the other characters the rule refuses as
// \uHHHH, and every other character as itself: 'Hips\xff', 'take\u202E4pm.exe', 'Hüfte'.
std::string QuotedNameText(absl::string_view text);

// `text` with each ill-formed UTF-8 sequence (its longest start of a well-formed sequence, or
// one byte) replaced by U+FFFD: for answering with text stored before the rule, which protobuf
// would not carry. Well-formed text comes back unchanged.
std::string ValidUtf8(absl::string_view text);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_NAME_TEXT_H_
