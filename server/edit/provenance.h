// Where a clip made by an operator came from (issue 16): the operator, the space it worked in,
// the source clips and ranges, and the request's parameters. Stored with the clip as JSON text
// (storage::ClipRecord::provenance) and shown by GetClip and `clip show`.
#ifndef MOTIONDB_SERVER_EDIT_PROVENANCE_H_
#define MOTIONDB_SERVER_EDIT_PROVENANCE_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"
#include "core/motion/clip.h"

namespace motiondb::server {

// A source range, at its clip's own rate.
struct SourceRange {
  int64_t clip_id = 0;
  FrameRange frames;
};

struct Provenance {
  std::string op;     // "scale", "smooth", ...
  std::string space;  // the space it worked in
  std::vector<SourceRange> sources{};
  std::string parameters_json{};  // a JSON object; "{}" when empty
};

std::string ProvenanceJson(const Provenance& provenance);
// nullopt for empty text (an ingested clip) or text that is not a provenance.
std::optional<Provenance> ParseProvenance(absl::string_view json);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_PROVENANCE_H_
