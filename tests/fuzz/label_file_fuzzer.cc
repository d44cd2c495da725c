// libFuzzer target: `motiondb labels import`'s reader (client/label_files.h), CSV and JSON. The
// input is a file's text, read as both. Nothing may crash or trip a sanitizer; a refusal is
// INVALID_ARGUMENT; a file that reads gives one place a label, and what FormatLabelFile writes
// of its labels reads back as the same labels.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <google/protobuf/util/message_differencer.h>

#include "client/label_files.h"

namespace {

using motiondb::cli::LabelFile;
using motiondb::cli::LabelFileFormat;

[[noreturn]] void Fail(const char* what, const std::string& detail) {
  std::fprintf(stderr, "%s: %s\n", what, detail.c_str());
  std::abort();
}

// The labels as stored ones, as `labels export` would have them: a clip by name or id and a
// range in frames (a label given in seconds is left out: export writes frames).
std::vector<motiondb::v1::Label> AsStored(const LabelFile& file) {
  std::vector<motiondb::v1::Label> labels;
  for (const motiondb::v1::NewLabel& given : file.labels) {
    if (given.has_start_s() || given.has_end_s() || given.clip_name().empty() ||
        given.clip_id() != 0 || !given.has_first_frame() || !given.has_last_frame()) {
      continue;
    }
    motiondb::v1::Label& label = labels.emplace_back();
    label.set_clip_name(given.clip_name());
    label.set_first_frame(given.first_frame());
    label.set_last_frame(given.last_frame());
    label.set_descriptor_name(given.descriptor_name());
    label.set_value(given.has_value() ? given.value() : 1.0);
  }
  return labels;
}

void Check(const std::string& text, LabelFileFormat format) {
  const absl::StatusOr<LabelFile> read = motiondb::cli::ParseLabelFile(text, format);
  if (!read.ok()) {
    if (read.status().code() != absl::StatusCode::kInvalidArgument) {
      Fail("a refusal that is not INVALID_ARGUMENT", read.status().ToString());
    }
    return;
  }
  if (read->places.size() != read->labels.size()) Fail("places", "one a label");
  const std::vector<motiondb::v1::Label> stored = AsStored(*read);
  const absl::StatusOr<LabelFile> again =
      motiondb::cli::ParseLabelFile(motiondb::cli::FormatLabelFile(stored, format), format);
  if (!again.ok()) Fail("an exported file does not read back", again.status().ToString());
  if (again->labels.size() != stored.size()) Fail("read back", "a different number of labels");
  for (size_t i = 0; i < stored.size(); ++i) {
    const motiondb::v1::NewLabel& back = again->labels[i];
    if (back.clip_name() != stored[i].clip_name() ||
        back.first_frame() != stored[i].first_frame() ||
        back.last_frame() != stored[i].last_frame() ||
        back.descriptor_name() != stored[i].descriptor_name() ||
        (back.has_value() ? back.value() : 1.0) != stored[i].value()) {
      Fail("read back differently", back.ShortDebugString() + " vs " + stored[i].ShortDebugString());
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Check(text, LabelFileFormat::kCsv);
  Check(text, LabelFileFormat::kJson);
  return 0;
}
