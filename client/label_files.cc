#include "client/label_files.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

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

// The fields of one CSV line: commas separate them, quotes ("...", with "" for a quote) keep
// commas inside one.
absl::StatusOr<std::vector<std::string>> SplitCsvLine(absl::string_view line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      fields.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  if (quoted) return absl::InvalidArgumentError("a quoted field is not closed");
  return fields;
}

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
    fields.clip_name = row[clip->second];
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
  fields.descriptor = row[columns.at("descriptor")];
  if (const auto unit = columns.find("unit"); unit != columns.end() && !row[unit->second].empty()) {
    fields.unit = row[unit->second];
  }
  return fields;
}

absl::StatusOr<LabelFile> ParseCsv(absl::string_view text) {
  // Spreadsheets saving "CSV UTF-8" begin the file with a byte order mark.
  absl::ConsumePrefix(&text, "\xEF\xBB\xBF");
  LabelFile file;
  std::optional<std::map<std::string, size_t>> columns;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    if (absl::EndsWith(line, "\r")) line.remove_suffix(1);
    if (absl::StripAsciiWhitespace(line).empty()) continue;
    const std::string place = absl::StrCat("line ", line_number);
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<std::string> row,
                              Prefixed(place, SplitCsvLine(line)));
    if (!columns) {
      MOTIONDB_ASSIGN_OR_RETURN(columns, Prefixed(place, CsvHeader(row)));
      continue;
    }
    MOTIONDB_ASSIGN_OR_RETURN(const LabelFields fields, Prefixed(place, CsvFields(row, *columns)));
    MOTIONDB_ASSIGN_OR_RETURN(file.labels.emplace_back(), Prefixed(place, ToNewLabel(fields)));
    file.places.push_back(place);
  }
  if (!columns) return absl::InvalidArgumentError("the file has no header line");
  return file;
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

absl::StatusOr<LabelFile> ParseJson(const std::string& text) {
  const nlohmann::json items = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (items.is_discarded()) return absl::InvalidArgumentError("not valid JSON");
  if (!items.is_array()) return absl::InvalidArgumentError("expected a list of labels");
  LabelFile file;
  for (size_t i = 0; i < items.size(); ++i) {
    const std::string place = absl::StrCat("item ", i);
    MOTIONDB_ASSIGN_OR_RETURN(const LabelFields fields, Prefixed(place, JsonFields(items[i])));
    MOTIONDB_ASSIGN_OR_RETURN(file.labels.emplace_back(), Prefixed(place, ToNewLabel(fields)));
    file.places.push_back(place);
  }
  return file;
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
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

absl::StatusOr<LabelFile> ParseLabelFile(const std::string& text, LabelFileFormat format) {
  return format == LabelFileFormat::kCsv ? ParseCsv(text) : ParseJson(text);
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
