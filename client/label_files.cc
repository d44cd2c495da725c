#include "client/label_files.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

constexpr const char* kColumns[] = {"clip",       "clip_id", "start", "end",
                                    "descriptor", "value",   "unit"};

bool IsDigits(absl::string_view text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](char c) { return absl::ascii_isdigit(c); });
}

// The shortest text that reads back as `value`.
std::string ShortestNumber(double value) {
  char buffer[32];
  const std::to_chars_result written = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, written.ptr);
}

// The largest frame number a file may give (what the API's int32 holds).
constexpr double kMaxFrame = std::numeric_limits<int32_t>::max();

// One label's fields as a file gives them, before they become a NewLabel.
struct LabelFields {
  std::optional<int64_t> clip_id;
  std::string clip_name;
  std::optional<double> start, end, value;
  std::string descriptor;
  std::string unit = "frames";
};

absl::StatusOr<v1::NewLabel> ToNewLabel(const LabelFields& fields) {
  v1::NewLabel label;
  if (!fields.clip_id && fields.clip_name.empty()) {
    return absl::InvalidArgumentError("clip: missing (give the clip's name, or its id as clip_id)");
  }
  // Both given, the server checks that they name one clip.
  if (fields.clip_id) label.set_clip_id(*fields.clip_id);
  label.set_clip_name(fields.clip_name);
  if (fields.unit == "seconds") {
    if (fields.start) label.set_start_s(*fields.start);
    if (fields.end) label.set_end_s(*fields.end);
  } else if (fields.unit == "frames") {
    for (const auto& [bound, name] : {std::pair{fields.start, "start"}, {fields.end, "end"}}) {
      // Checked before the cast, which is undefined for NaN, infinities and numbers out of range.
      if (bound && (!std::isfinite(*bound) || std::abs(*bound) > kMaxFrame)) {
        return absl::InvalidArgumentError(absl::StrCat(name, ": ", *bound,
                                                       " is not a frame number (at most ",
                                                       std::numeric_limits<int32_t>::max(), ")"));
      }
      if (bound && (*bound != static_cast<int32_t>(*bound))) {
        return absl::InvalidArgumentError(
            absl::StrCat(name, ": ", *bound, " is not a whole frame number"));
      }
    }
    if (fields.start) label.set_first_frame(static_cast<int32_t>(*fields.start));
    if (fields.end) label.set_last_frame(static_cast<int32_t>(*fields.end));
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("unit: '", fields.unit, "' is neither frames nor seconds"));
  }
  label.set_descriptor_name(fields.descriptor);
  if (fields.value) label.set_value(*fields.value);
  return label;
}

// OWASP's rule against formula injection: a spreadsheet runs a cell that begins with one of
// these as a formula (=cmd|' /C calc'!A0), unless an apostrophe comes first, which it hides.
bool StartsFormula(char c) {
  return c == '=' || c == '+' || c == '-' || c == '@' || c == '\t' || c == '\r';
}

// Whether `text` is a cell that export neutralised: an apostrophe, then what starts a formula
// or another apostrophe (so that a text beginning so is told apart, and comes back exactly).
bool IsNeutralised(absl::string_view text) {
  return text.size() >= 2 && text[0] == '\'' && (StartsFormula(text[1]) || text[1] == '\'');
}

// A text cell as export writes it: after an apostrophe when a spreadsheet would run it (or
// when it would read as neutralised); Restored() undoes it.
std::string Neutralised(const std::string& text) {
  if (!text.empty() && (StartsFormula(text[0]) || IsNeutralised(text))) return "'" + text;
  return text;
}

std::string Restored(std::string text) {
  if (IsNeutralised(text)) text.erase(0, 1);
  return text;
}

// A CSV file's records (RFC 4180), read from a stream a character at a time: commas separate
// the fields, quotes ("...", with "" for a quote) keep commas and line breaks inside one, and a
// line break outside quotes (LF or CRLF) ends a record. Blank lines are skipped.
class CsvRecords {
 public:
  // A record longer than this is a quote left open, not a label.
  static constexpr size_t kMaxRecordBytes = size_t{1} << 20;

  struct Record {
    std::vector<std::string> fields;
    int line = 0;  // where it starts
  };

  explicit CsvRecords(std::istream& in) : in_(*in.rdbuf()) {}

  // The next record, or nullopt at the end. INVALID_ARGUMENT naming the line the record starts
  // on for a quoted field not closed, or a record over kMaxRecordBytes.
  absl::StatusOr<std::optional<Record>> Next() {
    Record record{{""}, line_};
    bool quoted = false;
    bool blank = true;      // nothing but blanks yet
    bool after_cr = false;  // the last character was a CR outside quotes
    size_t bytes = 0;
    for (int c = in_.sbumpc();; c = in_.sbumpc()) {
      if (c == std::char_traits<char>::eof()) {
        if (quoted) return Unclosed(record.line);
        if (blank) return std::nullopt;
        return record;
      }
      if (++bytes > kMaxRecordBytes) {
        return absl::InvalidArgumentError(absl::StrCat("line ", record.line,
                                                       ": the record runs past ", kMaxRecordBytes,
                                                       " bytes (a quoted field not closed?)"));
      }
      const char ch = static_cast<char>(c);
      if (ch == '\n') ++line_;
      if (ch == '\n' && !quoted) {
        if (blank) {  // a blank line: the next record starts after it
          record = {{""}, line_};
          bytes = 0;
          continue;
        }
        if (after_cr) record.fields.back().pop_back();
        return record;
      }
      after_cr = ch == '\r' && !quoted;
      if (!absl::ascii_isspace(static_cast<unsigned char>(ch))) blank = false;
      if (quoted && ch == '"' && in_.sgetc() == '"') {
        in_.sbumpc();
        record.fields.back() += '"';
      } else if (ch == '"') {
        quoted = !quoted;
      } else if (ch == ',' && !quoted) {
        record.fields.emplace_back();
      } else {
        record.fields.back() += ch;
      }
    }
  }

 private:
  static absl::Status Unclosed(int line) {
    return absl::InvalidArgumentError(
        absl::StrCat("line ", line, ": a quoted field is not closed by the end of the file"));
  }

  std::streambuf& in_;
  int line_ = 1;
};

absl::StatusOr<std::optional<double>> CsvNumber(const std::string& text, const char* column) {
  if (text.empty()) return std::nullopt;
  double number = 0;
  if (!absl::SimpleAtod(text, &number)) {
    return absl::InvalidArgumentError(absl::StrCat(column, ": '", text, "' is not a number"));
  }
  return number;
}

// The header's column of each name, each named once; every column but unit is required, and
// clip and clip_id are one: either will do.
absl::StatusOr<std::map<std::string, size_t>> CsvHeader(const std::vector<std::string>& names) {
  std::map<std::string, size_t> columns;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string name = absl::AsciiStrToLower(absl::StripAsciiWhitespace(names[i]));
    if (std::find(std::begin(kColumns), std::end(kColumns), name) == std::end(kColumns)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "header: unknown column '", name, "'; the columns are ", absl::StrJoin(kColumns, ", ")));
    }
    if (const auto [known, added] = columns.emplace(name, i); !added) {
      return absl::InvalidArgumentError(absl::StrCat("header: column '", name, "' is named twice (",
                                                     known->second + 1, " and ", i + 1, ")"));
    }
  }
  if (!columns.contains("clip") && !columns.contains("clip_id")) {
    return absl::InvalidArgumentError("header: no 'clip' (or 'clip_id') column");
  }
  for (const char* required : {"start", "end", "descriptor", "value"}) {
    if (!columns.contains(required)) {
      return absl::InvalidArgumentError(absl::StrCat("header: no '", required, "' column"));
    }
  }
  return columns;
}

absl::StatusOr<LabelFields> CsvFields(const std::vector<std::string>& row,
                                      const std::map<std::string, size_t>& columns) {
  if (row.size() != columns.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(row.size(), " fields, but the header names ", columns.size()));
  }
  LabelFields fields;
  // clip is always a name, digits too; an id is a clip_id.
  if (const auto clip = columns.find("clip"); clip != columns.end()) {
    fields.clip_name = Restored(row[clip->second]);
  }
  if (const auto clip_id = columns.find("clip_id");
      clip_id != columns.end() && !row[clip_id->second].empty()) {
    const std::string& text = row[clip_id->second];
    int64_t id = 0;
    if (!IsDigits(text) || !absl::SimpleAtoi(text, &id) || id == 0) {
      return absl::InvalidArgumentError(absl::StrCat("clip_id: '", text, "' is not a clip id"));
    }
    fields.clip_id = id;
  }
  MOTIONDB_ASSIGN_OR_RETURN(fields.start, CsvNumber(row[columns.at("start")], "start"));
  MOTIONDB_ASSIGN_OR_RETURN(fields.end, CsvNumber(row[columns.at("end")], "end"));
  MOTIONDB_ASSIGN_OR_RETURN(fields.value, CsvNumber(row[columns.at("value")], "value"));
  fields.descriptor = Restored(row[columns.at("descriptor")]);
  if (const auto unit = columns.find("unit"); unit != columns.end() && !row[unit->second].empty()) {
    fields.unit = row[unit->second];
  }
  return fields;
}

absl::Status ReadCsv(std::istream& in, const LabelConsumer& consume) {
  CsvRecords records(in);
  std::optional<std::map<std::string, size_t>> columns;
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(std::optional<CsvRecords::Record> record, records.Next());
    if (!record) break;
    const std::string place = absl::StrCat("line ", record->line);
    if (!columns) {
      // Spreadsheets saving "CSV UTF-8" begin the file with a byte order mark.
      absl::string_view first = record->fields[0];
      if (absl::ConsumePrefix(&first, "\xEF\xBB\xBF")) record->fields[0] = std::string(first);
      MOTIONDB_ASSIGN_OR_RETURN(columns, Prefixed(place, CsvHeader(record->fields)));
      continue;
    }
    MOTIONDB_ASSIGN_OR_RETURN(const LabelFields fields,
                              Prefixed(place, CsvFields(record->fields, *columns)));
    MOTIONDB_ASSIGN_OR_RETURN(v1::NewLabel label, Prefixed(place, ToNewLabel(fields)));
    MOTIONDB_RETURN_IF_ERROR(consume({std::move(label), place}));
  }
  if (!columns) return absl::InvalidArgumentError("the file has no header line");
  return absl::OkStatus();
}

// A JSON field that may be absent or null: a number, or INVALID_ARGUMENT naming `key`.
absl::StatusOr<std::optional<double>> JsonNumber(const nlohmann::json& item, const char* key) {
  if (!item.contains(key) || item[key].is_null()) return std::nullopt;
  if (!item[key].is_number()) {
    return absl::InvalidArgumentError(absl::StrCat(key, ": expected a number"));
  }
  return item[key].get<double>();
}

absl::StatusOr<LabelFields> JsonFields(const nlohmann::json& item) {
  if (!item.is_object()) return absl::InvalidArgumentError("expected an object");
  for (const auto& [key, unused] : item.items()) {
    if (std::find(std::begin(kColumns), std::end(kColumns), key) == std::end(kColumns)) {
      return absl::InvalidArgumentError(absl::StrCat("unknown key '", key, "'"));
    }
  }
  LabelFields fields;
  if (item.contains("clip")) {
    if (!item["clip"].is_string()) {
      return absl::InvalidArgumentError("clip: expected a clip name (give an id as clip_id)");
    }
    fields.clip_name = item["clip"].get<std::string>();
  }
  if (item.contains("clip_id")) {
    if (!item["clip_id"].is_number_unsigned() || item["clip_id"].get<uint64_t>() == 0 ||
        item["clip_id"].get<uint64_t>() > std::numeric_limits<int64_t>::max()) {
      return absl::InvalidArgumentError("clip_id: expected a clip id (a whole number from 1)");
    }
    fields.clip_id = item["clip_id"].get<int64_t>();
  }
  if (!item.value("descriptor", nlohmann::json()).is_string()) {
    return absl::InvalidArgumentError("descriptor: expected a string");
  }
  fields.descriptor = item["descriptor"].get<std::string>();
  MOTIONDB_ASSIGN_OR_RETURN(fields.start, JsonNumber(item, "start"));
  MOTIONDB_ASSIGN_OR_RETURN(fields.end, JsonNumber(item, "end"));
  MOTIONDB_ASSIGN_OR_RETURN(fields.value, JsonNumber(item, "value"));
  if (item.contains("unit")) {
    if (!item["unit"].is_string()) return absl::InvalidArgumentError("unit: expected a string");
    fields.unit = item["unit"].get<std::string>();
  }
  return fields;
}

// Thrown from nlohmann's parser callback to stop the parse at the first error, which `status`
// then holds.
struct StopParsing {};

absl::Status ReadJson(std::istream& in, const LabelConsumer& consume) {
  using Event = nlohmann::json::parse_event_t;
  absl::Status status;
  bool list = false;
  size_t item = 0;
  // Each item of the list, once parsed whole, is handed on and dropped from the list, so that
  // one item at a time is held.
  const nlohmann::json::parser_callback_t each_item = [&](int depth, Event event,
                                                          nlohmann::json& parsed) {
    if (depth == 0) {
      if (event == Event::array_start) list = true;
      if (list) return true;
      status = absl::InvalidArgumentError("expected a list of labels");
      throw StopParsing();
    }
    const bool whole = depth == 1 && (event == Event::object_end || event == Event::array_end ||
                                      event == Event::value);
    if (!whole) return true;
    const std::string place = absl::StrCat("item ", item++);
    status = [&]() -> absl::Status {
      MOTIONDB_ASSIGN_OR_RETURN(const LabelFields fields, Prefixed(place, JsonFields(parsed)));
      MOTIONDB_ASSIGN_OR_RETURN(v1::NewLabel label, Prefixed(place, ToNewLabel(fields)));
      return consume({std::move(label), place});
    }();
    if (!status.ok()) throw StopParsing();
    return false;
  };
  try {
    [[maybe_unused]] const nlohmann::json emptied = nlohmann::json::parse(in, each_item);
  } catch (const StopParsing&) {
    return status;
  } catch (const nlohmann::json::exception& error) {
    // "[json.exception.parse_error.101] parse error at line 2, column 5: ..."
    absl::string_view what = error.what();
    if (const size_t end = what.find("] "); end != absl::string_view::npos) {
      what.remove_prefix(end + 2);
    }
    return absl::InvalidArgumentError(absl::StrCat("not valid JSON: ", what));
  }
  return absl::OkStatus();
}

// A text cell: neutralised, then quoted when it holds a comma, a quote or a line break.
std::string CsvField(const std::string& text) {
  const std::string cell = Neutralised(text);
  if (cell.find_first_of(",\"\r\n") == std::string::npos) return cell;
  std::string quoted = "\"";
  for (const char c : cell) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

absl::StatusOr<LabelFileFormat> LabelFileFormatOf(const std::string& path) {
  const std::string lower = absl::AsciiStrToLower(path);
  if (absl::EndsWith(lower, ".csv")) return LabelFileFormat::kCsv;
  if (absl::EndsWith(lower, ".json")) return LabelFileFormat::kJson;
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": expected a .csv or .json file (the extension says which)"));
}

absl::Status ReadLabelFile(std::istream& in, LabelFileFormat format, const LabelConsumer& consume) {
  return format == LabelFileFormat::kCsv ? ReadCsv(in, consume) : ReadJson(in, consume);
}

absl::StatusOr<LabelFile> ParseLabelFile(const std::string& text, LabelFileFormat format) {
  std::istringstream in(text);
  LabelFile file;
  MOTIONDB_RETURN_IF_ERROR(ReadLabelFile(in, format, [&file](PlacedLabel placed) {
    file.labels.push_back(std::move(placed.label));
    file.places.push_back(std::move(placed.place));
    return absl::OkStatus();
  }));
  return file;
}

std::string FormatLabelFile(const std::vector<v1::Label>& labels, LabelFileFormat format) {
  if (format == LabelFileFormat::kJson) {
    nlohmann::json items = nlohmann::json::array();
    for (const v1::Label& label : labels) {
      items.push_back({{"clip", label.clip_name()},
                       {"start", label.first_frame()},
                       {"end", label.last_frame()},
                       {"descriptor", label.descriptor_name()},
                       {"value", label.value()},
                       {"unit", "frames"}});
    }
    return items.dump(1) + "\n";
  }
  std::string text = "clip,start,end,descriptor,value,unit\n";
  for (const v1::Label& label : labels) {
    // By name, which another database knows the clip by too.
    absl::StrAppend(&text, CsvField(label.clip_name()), ",", label.first_frame(), ",",
                    label.last_frame(), ",", CsvField(label.descriptor_name()), ",",
                    ShortestNumber(label.value()), ",frames\n");
  }
  return text;
}

}  // namespace motiondb::cli
