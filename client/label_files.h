// The label files `labels import` reads and `labels export` writes: what studio labelling tools
// exchange. CSV (RFC 4180) with a header naming the columns clip (or clip_id, or both), start,
// end, descriptor, value, and optionally unit (frames, the default, or seconds), in any order,
// each once; fields holding a comma, a quote or a line break are quoted ("a, b", "say ""hi""");
// a UTF-8 byte order mark before the header is skipped. JSON: a list of objects with the same
// keys. clip is always the clip's name, digits too ("0012" is the clip named 0012); clip_id its
// id. Given both, they must name one clip. An empty (or absent) start or end is the clip's first
// or last frame, an empty value 1.
//
// A CSV text cell (clip, descriptor) that a spreadsheet would run as a formula, one beginning
// with = + - @, a tab or a CR (OWASP's rule), is written after an apostrophe, which spreadsheets
// hide ("'=cmd|' /C calc'!A0"); so is one beginning with an apostrophe and one of those or
// another apostrophe, so that reading drops the apostrophe of exactly those cells and a file
// reads back as written.
#ifndef MOTIONDB_CLIENT_LABEL_FILES_H_
#define MOTIONDB_CLIENT_LABEL_FILES_H_

#include <functional>
#include <istream>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motiondb/v1/label_service.pb.h"

namespace motiondb::cli {

enum class LabelFileFormat { kCsv, kJson };

// .csv or .json (any case); INVALID_ARGUMENT naming the file otherwise.
absl::StatusOr<LabelFileFormat> LabelFileFormatOf(const std::string& path);

// One label of a file and where it stands: "line 5" (CSV: the line its record starts on) or
// "item 3" (JSON).
struct PlacedLabel {
  v1::NewLabel label;
  std::string place;
};
using LabelConsumer = std::function<absl::Status(PlacedLabel)>;

// Reads a label file from `in` a label at a time, handing each to `consume`, whose first error
// stops the reading and is returned: what is held does not grow with the file (a JSON item, a
// CSV record of at most 1 MiB). Errors say where ("line 4: value 'x' is not a number").
absl::Status ReadLabelFile(std::istream& in, LabelFileFormat format, const LabelConsumer& consume);

struct LabelFile {
  std::vector<v1::NewLabel> labels;
  // Where each label stands in the file, for errors: "line 5" (CSV) or "item 3" (JSON).
  std::vector<std::string> places;
};

// ReadLabelFile's labels of a whole `text`.
absl::StatusOr<LabelFile> ParseLabelFile(const std::string& text, LabelFileFormat format);

// `labels` in a file ParseLabelFile reads back as the same labels: the clip by name (in clip),
// the range in frames. It has no origin column: what it holds imports as manual labels.
std::string FormatLabelFile(const std::vector<v1::Label>& labels, LabelFileFormat format);

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_LABEL_FILES_H_
