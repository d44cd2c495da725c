// The label files `labels import` reads and `labels export` writes: what studio labelling tools
// exchange. CSV with a header naming the columns clip, start, end, descriptor, value, and
// optionally unit (frames, the default, or seconds), in any order; fields holding a comma or a
// quote are quoted ("a, b", "say ""hi"""). JSON: a list of objects with the same keys. A clip
// is its id (a CSV field of digits, a JSON number) or its name; an empty (or absent) start or
// end is the clip's first or last frame, an empty value 1.
#ifndef MOTIONDB_CLIENT_LABEL_FILES_H_
#define MOTIONDB_CLIENT_LABEL_FILES_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motiondb/v1/label_service.pb.h"

namespace motiondb::cli {

enum class LabelFileFormat { kCsv, kJson };

// .csv or .json (any case); INVALID_ARGUMENT naming the file otherwise.
absl::StatusOr<LabelFileFormat> LabelFileFormatOf(const std::string& path);

struct LabelFile {
  std::vector<v1::NewLabel> labels;
  // Where each label stands in the file, for errors: "line 5" (CSV) or "item 3" (JSON).
  std::vector<std::string> places;
};

// Parses a label file's `text`; errors say where ("line 4: value 'x' is not a number").
absl::StatusOr<LabelFile> ParseLabelFile(const std::string& text, LabelFileFormat format);

// `labels` in a file ParseLabelFile reads back as the same labels: the clip by name, the range
// in frames.
std::string FormatLabelFile(const std::vector<v1::Label>& labels, LabelFileFormat format);

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_LABEL_FILES_H_
