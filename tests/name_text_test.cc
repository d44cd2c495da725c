// The rule for names' text (util/name_text.h) on its own: what passes, what is refused and where,
// and the repair of text stored before the rule.
#include "util/name_text.h"

#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

TEST(NameText, PrintableUtf8Passes) {
  for (const std::string text :
       {"walk_01", "session1/take 2: left (fast)", "Hüfte", "腰", "ручка", "שלום 2",
        "emoji \xF0\x9F\x98\x80", "zero\xE2\x80\x8Bwidth", "\xEF\xBF\xBD", "max \xF4\x8F\xBF\xBF",
        "'=cmd|' /C calc'!A0", ""}) {
    EXPECT_EQ(FindNameTextProblem(text), std::nullopt) << text;
    EXPECT_TRUE(CheckNameText("name", text).ok()) << text;
  }
}

TEST(NameText, RefusesWhatHidesOrReordersTextWithWhereAndWhat) {
  const std::vector<std::tuple<std::string, size_t, std::string>> cases = {
      // Ill-formed UTF-8: a Latin-1 byte, a lone continuation byte, a cut sequence, overlong
      // forms, a surrogate, past U+10FFFF, bytes never in UTF-8.
      {"Hips\xFF", 4, "invalid UTF-8"},
      {"H\xFC"
       "fte",
       1, "invalid UTF-8"},
      {"a\x80", 1, "invalid UTF-8"},
      {"ab\xE2\x80", 2, "invalid UTF-8"},
      {"\xC0\xAF", 0, "invalid UTF-8"},
      {"x\xE0\x80\xAF", 1, "invalid UTF-8"},
      {"\xED\xA0\x80", 0, "invalid UTF-8"},
      {"\xF4\x90\x80\x80", 0, "invalid UTF-8"},
      {"\xF5\x80\x80\x80", 0, "invalid UTF-8"},
      // Control characters: C0, NUL, DEL and C1.
      {"step\x1b[2J", 4, "a control character"},
      {std::string("a\0b", 3), 1, "a control character"},
      {"tab\there", 3, "a control character"},
      {"del\x7F", 3, "a control character"},
      {"take\xC2\x85one", 4, "a control character"},
      // Bidi_Control: overrides, embeddings, isolates and marks.
      {"txt.\xE2\x80\xAE"
       "fdp",
       4, "the bidirectional control U+202E"},
      {"\xE2\x80\xAA", 0, "the bidirectional control U+202A"},
      {"a\xE2\x81\xA6"
       "b",
       1, "the bidirectional control U+2066"},
      {"a\xE2\x81\xA9", 1, "the bidirectional control U+2069"},
      {"walk\xE2\x80\x8E", 4, "the bidirectional control U+200E"},
      {"walk\xE2\x80\x8F", 4, "the bidirectional control U+200F"},
      {"\xD8\x9C", 0, "the bidirectional control U+061C"},
      // Line and paragraph separators.
      {"two\xE2\x80\xA8lines", 3, "the line separator U+2028"},
      {"two\xE2\x80\xA9paragraphs", 3, "the paragraph separator U+2029"},
  };
  for (const auto& [text, byte, what] : cases) {
    const std::optional<NameTextProblem> problem = FindNameTextProblem(text);
    ASSERT_TRUE(problem.has_value()) << absl::CHexEscape(text);
    EXPECT_EQ(problem->byte, byte) << absl::CHexEscape(text);
    EXPECT_EQ(problem->what, what) << absl::CHexEscape(text);
    const absl::Status status = CheckNameText("joint name", text);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(status.message()),
                HasSubstr(absl::StrCat("holds ", what, " at byte ", byte, "; names are")));
    EXPECT_THAT(std::string(status.message()), ::testing::StartsWith("joint name '"));
    // The message is itself printable text: the name is escaped.
    EXPECT_EQ(FindNameTextProblem(status.message()), std::nullopt) << status.message();
  }
}

TEST(NameText, NamesAreQuotedReadablyWithWhatTheRuleRefusesEscaped) {
  for (const auto& [text, quoted] :
       std::vector<std::pair<std::string, std::string>>{{"walk", "'walk'"},
                                                        {"H\xC3\xBC"
                                                         "fte",
                                                         "'H\xC3\xBC"
                                                         "fte'"},
                                                        {"Hips\xFF", "'Hips\\xff'"},
                                                        {"H\xFC"
                                                         "fte",
                                                         "'H\\xfcfte'"},
                                                        {"take\xE2\x80\xAE"
                                                         "4pm.exe",
                                                         "'take\\u202E4pm.exe'"},
                                                        {"step\x1b[2J", "'step\\x1b[2J'"},
                                                        {"a\tb\nc\rd\\e", "'a\\tb\\nc\\rd\\\\e'"},
                                                        {"nel\xC2\x85", "'nel\\u0085'"},
                                                        {"two\xE2\x80\xA8", "'two\\u2028'"}}) {
    EXPECT_EQ(QuotedNameText(text), quoted);
    EXPECT_EQ(FindNameTextProblem(QuotedNameText(text)), std::nullopt) << quoted;
  }
  // Shortened after whole characters.
  EXPECT_EQ(QuotedNameText(std::string(79, 'a') + "\xC3\xBC"
                                                  "bc"),
            "'" + std::string(79, 'a') + "\xC3\xBC...'");
}

TEST(NameText, ALongNameIsShownShortened) {
  const absl::Status status = CheckNameText("tag", std::string(200, 'a') + "\x01");
  EXPECT_THAT(std::string(status.message()), HasSubstr(std::string(80, 'a') + "...'"));
  EXPECT_THAT(std::string(status.message()), HasSubstr("at byte 200"));
}

TEST(NameText, ValidUtf8ReplacesEachIllFormedSequenceOnce) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"Hips", "Hips"},
      {"H\xC3\xBC"
       "fte",
       "H\xC3\xBC"
       "fte"},
      {"Hips\xFF", "Hips\xEF\xBF\xBD"},
      {"\xFF\xFE", "\xEF\xBF\xBD\xEF\xBF\xBD"},
      // A cut three-byte sequence is one subpart: one U+FFFD.
      {"a\xE2\x80"
       "b",
       "a\xEF\xBF\xBD"
       "b"},
      // An overlong lead byte and its continuation: two.
      {"\xC0\xAF", "\xEF\xBF\xBD\xEF\xBF\xBD"},
      // A surrogate: its lead byte cannot start one, then two lone continuations.
      {"\xED\xA0\x80", "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD"},
      // Controls and bidi characters are well-formed: kept (the rule refuses them on entry).
      {"a\xE2\x80\xAE"
       "b",
       "a\xE2\x80\xAE"
       "b"},
  };
  for (const auto& [text, valid] : cases) {
    EXPECT_EQ(ValidUtf8(text), valid) << absl::CHexEscape(text);
    const std::optional<NameTextProblem> problem = FindNameTextProblem(ValidUtf8(text));
    EXPECT_TRUE(!problem || problem->what != "invalid UTF-8") << absl::CHexEscape(text);
  }
}

}  // namespace
}  // namespace motiondb
